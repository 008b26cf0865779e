//! What differs between control families, as data.

use fiveaxis_gcode::Syntax;
use fiveaxis_machine::Control;

/// Per-control facts the controller consults.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dialect {
    /// Deepest subprogram nesting (FANUC 30i: 10 levels, 16/18: 4,
    /// Mitsubishi: 8).
    pub max_nesting: usize,
    /// Deepest nesting of macro calls (G65, G66) with their own local
    /// variables: as `max_nesting` except on Haas, whose G65 calls nest 9
    /// deep (Haas NGC mill operator's manual, 2017, "G65 Macro Subprogram
    /// Call").
    pub max_macro_nesting: usize,
    /// Most M codes in one block (FANUC No.3404#7 M3B: 3).
    pub max_m_codes: usize,
    /// G44 cancels tool length compensation (and TCPC) without moving
    /// (Mitsubishi, seed 004) instead of compensating in the − direction.
    pub g44_cancels: bool,
    /// The TCPC start-up block moves under TCPC (tip controlled), and not
    /// at all without axis words (Mitsubishi); otherwise it moves with
    /// tool length compensation only (FANUC, seed 000).
    pub tcpc_startup_controls_tip: bool,
    /// How the front end reads a line (comments).
    pub syntax: Syntax,
    /// P of G04 and of the dwell cycles (G82, G88, G89) is seconds when
    /// written with a decimal point and milliseconds without (Haas mill
    /// operator's manual, G04: `G04 P10.` is 10 s, `G04 P10` 10 ms).
    /// Otherwise P is an integer of milliseconds and a decimal point is an
    /// alarm (FANUC PS0007).
    pub dwell_p_seconds_with_point: bool,
    /// G87 is "bore in, manual retract" (Haas mill operator's manual,
    /// G87; Haas's back boring is G77) instead of FANUC's back boring.
    pub g87_manual_retract: bool,
    /// Haas's own codes (Haas NGC mill operator's manual): G234 tool
    /// centre point control, G254 / G255 dynamic work offset, G268 / G269
    /// feature coordinates and G253, G187 smoothness, G154 P1–P99 and
    /// G110–G129 work offsets, and Haas's standard M codes (M10–M13 the
    /// brakes of the fourth and fifth axes). `controller/haas.rs`.
    pub haas_codes: bool,
    /// P of G04 and the dwell cycles is seconds however it is written
    /// (LinuxCNC g-code.adoc, G4: "P - seconds to dwell").
    pub dwell_p_seconds: bool,
    /// Numbers count in whole units whether or not they have a decimal
    /// point (LinuxCNC has no least-input-increment rule: `X1` is 1 mm).
    pub calculator_input: bool,
    /// The program is read as RS274/NGC (LinuxCNC): o-words, named
    /// parameters, `;` comments, assignments after the line is read.
    pub rs274ngc: bool,
    /// Structured IF: `IF [cond] THEN` alone on its line, blocks, an
    /// optional `ELSE`, `ENDIF` (Mitsubishi M800/M80 programming manual,
    /// user macro control commands; Mazak's EIA/ISO programs on its
    /// Mitsubishi-based controls). FANUC's custom macro B has the one-line
    /// `IF [cond] THEN #n = value` only.
    pub structured_if: bool,
}

impl Dialect {
    /// The table for `control`.
    pub fn of(control: Control) -> Self {
        let fanuc = |max_nesting| Self {
            max_nesting,
            max_macro_nesting: max_nesting,
            max_m_codes: 3,
            g44_cancels: false,
            tcpc_startup_controls_tip: false,
            syntax: Syntax::FANUC,
            dwell_p_seconds_with_point: false,
            g87_manual_retract: false,
            haas_codes: false,
            dwell_p_seconds: false,
            calculator_input: false,
            rs274ngc: false,
            structured_if: false,
        };
        match control {
            Control::Fanuc30i => fanuc(10),
            Control::Fanuc16 => fanuc(4),
            Control::Mitsubishi => Self {
                max_nesting: 8,
                max_macro_nesting: 8,
                max_m_codes: 4,
                g44_cancels: true,
                tcpc_startup_controls_tip: true,
                syntax: Syntax::FANUC,
                dwell_p_seconds_with_point: false,
                g87_manual_retract: false,
                haas_codes: false,
                dwell_p_seconds: false,
                calculator_input: false,
                rs274ngc: false,
                structured_if: true,
            },
            Control::Mazak => Self {
                max_nesting: 8,
                max_macro_nesting: 8,
                max_m_codes: 4,
                g44_cancels: false,
                tcpc_startup_controls_tip: false,
                syntax: Syntax::FANUC,
                dwell_p_seconds_with_point: false,
                g87_manual_retract: false,
                haas_codes: false,
                dwell_p_seconds: false,
                calculator_input: false,
                rs274ngc: false,
                structured_if: true,
            },
            // Haas's reading rules; its M98 nesting depth and M codes per
            // block are not sourced yet (issue #15): FANUC 30i's stand in.
            Control::Haas => Self {
                max_macro_nesting: 9,
                syntax: Syntax::HAAS,
                dwell_p_seconds_with_point: true,
                g87_manual_retract: true,
                haas_codes: true,
                ..fanuc(10)
            },
            // LinuxCNC's interpreter (o-code.adoc: "The maximum subroutine
            // nesting level is 10"; overview.adoc: "A line may have zero to
            // four M words").
            // SINUMERIK reads its own language (the `fiveaxis-sinumerik`
            // front end): what reaches the controller are commands, whose
            // values are whole units (a Siemens number without a decimal
            // point is not counted in increments).
            // HEIDENHAIN reads Klartext through its own front end
            // (`crate::heidenhain`); the commands reach the controller in
            // whole units, as SINUMERIK's do.
            Control::Sinumerik | Control::Heidenhain => Self {
                max_nesting: 16,
                max_macro_nesting: 16,
                max_m_codes: 5,
                calculator_input: true,
                ..fanuc(10)
            },
            Control::LinuxCnc => Self {
                max_nesting: 10,
                max_m_codes: 4,
                syntax: Syntax::LINUXCNC,
                dwell_p_seconds: true,
                calculator_input: true,
                rs274ngc: true,
                ..fanuc(10)
            },
        }
    }
}
