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
    /// G44 cancels tool length compensation (and TCPC) without moving
    /// (Mitsubishi, seed 004) instead of compensating in the − direction.
    pub g44_cancels: bool,
    /// The TCPC start-up block moves under TCPC (tip controlled), and not
    /// at all without axis words (Mitsubishi); otherwise it moves with
    /// tool length compensation only (FANUC, seed 000).
    pub tcpc_startup_controls_tip: bool,
}

impl Dialect {
    /// The table for `control`.
    pub fn of(control: Control) -> Self {
        let fanuc = |max_nesting| Self {
            max_nesting,
            max_m_codes: 3,
            g44_cancels: false,
            tcpc_startup_controls_tip: false,
        };
        match control {
            Control::Fanuc30i => fanuc(10),
            Control::Fanuc16 => fanuc(4),
            Control::Mitsubishi => Self {
                max_nesting: 8,
                max_m_codes: 4,
                g44_cancels: true,
                tcpc_startup_controls_tip: true,
            },
            Control::Mazak => Self {
                max_nesting: 8,
                max_m_codes: 4,
                g44_cancels: false,
                tcpc_startup_controls_tip: false,
            },
        }
    }
}
