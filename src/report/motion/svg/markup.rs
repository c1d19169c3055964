//! Numbers and text as the picture writes them: decimals without trailing zeros or `-0`, the
//! slow-motion factor in words, XML escapes and names fit for an `id`.

/// `x` with `decimals` decimals, trailing zeros dropped, never `-0`.
pub(super) fn num(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" { "0".into() } else { s }
}

/// The factor in words: `×40 slower`, `×2.5 faster`, `real time`.
pub(super) fn factor_words(f: f64) -> String {
    if f == 1.0 {
        "real time".into()
    } else if f > 1.0 {
        format!("×{} slower", num(f, 3))
    } else {
        format!("×{} faster", num(1.0 / f, 3))
    }
}

/// Text safe inside an XML element or attribute (also the FMU's `modelDescription.xml`).
pub(crate) fn xml(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if (c as u32) < 0x20 && c != '\t' && c != '\n' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// A name usable in an `id` (ASCII letters, digits, `-` and `_`; anything else becomes `_`).
pub(super) fn id_part(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// `x` with exactly `decimals` decimals (the time labels keep their width), never `-0`.
pub(super) fn num_fixed(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_string()
    } else {
        s
    }
}
