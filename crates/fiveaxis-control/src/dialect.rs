//! What differs between control families, as data.

use fiveaxis_machine::Control;

/// Per-control facts the controller consults.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dialect {
    /// Deepest subprogram nesting (FANUC 30i: 10 levels, 16/18: 4,
    /// Mitsubishi: 8).
    pub max_nesting: usize,
    /// Most M codes in one block (FANUC No.3404#7 M3B: 3).
    pub max_m_codes: usize,
}

impl Dialect {
    /// The table for `control`.
    pub fn of(control: Control) -> Self {
        match control {
            Control::Fanuc30i => Self {
                max_nesting: 10,
                max_m_codes: 3,
            },
            Control::Fanuc16 => Self {
                max_nesting: 4,
                max_m_codes: 3,
            },
            Control::Mitsubishi | Control::Mazak => Self {
                max_nesting: 8,
                max_m_codes: 4,
            },
        }
    }
}
