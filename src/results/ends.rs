//! Why a phase, or a contact's hold, ended: the one vocabulary of ends that the solvers
//! produce, the results store and the report alone puts into words.

use crate::model::ModelInfo;

/// A contact of a system: its index in the system's contacts (the order of
/// [`ModelInfo::contacts`]) and its name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ContactId {
    /// Its index in the system's contacts.
    pub index: usize,
    /// Its name in the spec.
    pub name: &'static str,
}

impl ContactId {
    /// Contact `index` of `info`'s system, if it has one there.
    pub fn of(info: &ModelInfo, index: usize) -> Option<ContactId> {
        (info.contacts.get(index)).map(|c| ContactId {
            index,
            name: c.name,
        })
    }
}

/// Why a phase ended, or a contact stopped holding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndCause {
    /// The contact's force reached zero: it opens (the first contact's is the separation).
    Force(ContactId),
    /// The contact's point ran off the edge of a body.
    Edge(ContactId),
    /// The contact's gap closed: the bodies meet (the run ends there unless it goes on through
    /// impacts).
    Contact(ContactId),
    /// The impulses of an impact elsewhere opened the contact.
    Impact,
    /// The reduced angle reached the model's end angle (the rod lies on the floor).
    Floor,
    /// The run reached the time it was asked to go on to (a scene's `until`).
    Until,
}

impl EndCause {
    /// Whether contact `index`'s force ended it.
    pub fn is_force_of(self, index: usize) -> bool {
        matches!(self, EndCause::Force(c) if c.index == index)
    }

    /// The contact whose event it is (its force, its edge, its gap closing), if any.
    pub fn contact(self) -> Option<ContactId> {
        match self {
            EndCause::Force(c) | EndCause::Edge(c) | EndCause::Contact(c) => Some(c),
            EndCause::Impact | EndCause::Floor | EndCause::Until => None,
        }
    }
}
