//! Emission: turns a presented [`Derivation`] into template contexts (flat data, computed
//! here) and renders the tera templates of `templates/` into Rust, LaTeX and JSON text.
//!
//! Below the writers: [`latex`] (an expression as LaTeX), [`lower`] (expressions as
//! straight-line Rust) and [`method`] (a generated method's head and preamble). The Rust writer
//! ([`rust`]) is built from [`code`], [`info`], [`docs`], [`constants`], [`state`] and
//! [`reduced`]; the LaTeX writer is [`tex`], the JSON writer [`json`]; [`common`] holds what
//! they share.

pub mod code;
pub mod common;
pub mod constants;
pub mod docs;
pub mod info;
pub mod json;
pub mod latex;
pub mod lower;
pub mod method;
pub mod reduced;
pub mod rust;
pub mod state;
pub mod tangents;
pub mod tape;
pub mod tex;

pub use common::{COMMAND, one_line, spec_path};
pub use info::{PhaseEntry, type_name};
pub use json::json_record;
pub use rust::{RustContext, rust_context};
pub use tex::{Equation, TexContext, TexParam, latex_name, tex_context, tex_text};

#[cfg(doc)]
use crate::derive::types::Derivation;

#[cfg(test)]
mod tests {
    use super::{latex_name, one_line, tex_text};

    #[test]
    fn names_as_people_write_them_print_with_subscripts() {
        let t = Some("theta");
        assert_eq!(latex_name("m1", t), "m_{\\mathrm{1}}");
        assert_eq!(latex_name("mA", t), "m_{\\mathrm{A}}");
        assert_eq!(latex_name("yB", t), "y_{\\mathrm{B}}");
        assert_eq!(latex_name("theta0", t), "\\theta_{\\mathrm{0}}");
        assert_eq!(latex_name("dot_xA", t), "\\dot{x}_{\\mathrm{A}}");
        assert_eq!(latex_name("ddot_x1", t), "\\ddot{x}_{\\mathrm{1}}");
        assert_eq!(latex_name("dot_theta", t), "\\dot{\\theta}");
        assert_eq!(latex_name("x_rest", t), "x_{\\mathrm{rest}}");
        // A capital alone, or a word, has no subscript to take.
        assert_eq!(latex_name("R", t), "R");
        assert_eq!(latex_name("W", t), "W");
        assert_eq!(latex_name("ell", t), "\\ell");
        assert_eq!(latex_name("mass", t), "\\mathrm{mass}");
    }

    #[test]
    fn spec_text_cannot_leave_a_comment_or_run_as_tex() {
        assert_eq!(one_line("a\n  pub fn evil() {}\r\n"), "a pub fn evil() {}");
        assert_eq!(
            tex_text("\\input{/etc/passwd} 50% of m_1 & N >= 0\n\\end"),
            "\\textbackslash{}input\\{/etc/passwd\\} 50\\% of m\\_1 \\& N \\textgreater{}= 0 \\textbackslash{}end"
        );
        assert_eq!(tex_text("m/s^2"), "m/s\\^{}2");
    }
}
