//! The system variables of custom macro B that read and write the
//! controller's state (FANUC 30i operator's manual, "System variables"):
//! tool offsets, work offsets, modal information and positions.
//!
//! Numbers (FANUC, tool offset memory C):
//!
//! | variables | what |
//! |---|---|
//! | `#2001`–`#2200`, `#10001`–`#10999` | tool length wear of H 1 … |
//! | `#2201`–`#2400`, `#11001`–`#11999` | tool length geometry |
//! | `#2401`–`#2600`, `#12001`–`#12999` | cutter radius wear of D 1 … |
//! | `#2601`–`#2800`, `#13001`–`#13999` | cutter radius geometry |
//! | `#5201`–`#5203` | external work offset X, Y, Z |
//! | `#5221`–`#5223` … `#5321`–`#5323` | G54 … G59 X, Y, Z (20 apart) |
//! | `#7001`–`#7003` … `#7941`–`#7943` | G54.1 P1 … P48 X, Y, Z (20 apart) |
//! | `#4001`–`#4030`, `#4201`–`#4230` | modal G codes of groups 1 … 30 |
//! | `#4101`–`#4130`, `#4301`–`#4330` | B D E F H M N O S T P codes |
//! | `#5001`+ | end point of the last block, workpiece coordinates, per axis |
//! | `#5021`+ | machine coordinates, per axis |
//! | `#5041`+ | current position, workpiece coordinates (= `#5001`+ here) |
//! | `#5061`+ | skip position (no skip signal: the block end) |
//!
//! Work offsets are read and written for X, Y, Z (the offsets file holds
//! no rotary work offsets: other axes read 0 and refuse writes). Writes of
//! positions and modal information are refused (read-only), as on the
//! control.

use fiveaxis_machine::MAX_TOOL_OFFSET;

use super::Controller;
use crate::modal::{
    CuttingMode, Distance, FeedMode, LengthMode, MotionMode, Plane, TcpcType, Units, WorkSelect,
};

/// Why a system variable cannot be read or written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SystemVarFault {
    /// The number is not a system variable the kernel has.
    Unknown,
    /// The variable can only be read.
    ReadOnly,
}

/// A tool offset field.
#[derive(Clone, Copy)]
enum ToolField {
    LengthWear,
    Length,
    RadiusWear,
    Radius,
}

/// The tool offset field and offset number of a variable number. FANUC
/// (memory C): `#2001`+ length wear, `#2201`+ length, `#2401`+ radius
/// wear, `#2601`+ radius. Haas (`haas`): `#2001`+ length, `#2201`+ length
/// wear, `#2401`+ diameter / radius (the kernel's radius, Setting 40 =
/// RADIUS), `#2601`+ its wear.
fn tool_variable(n: u32, haas: bool) -> Option<(ToolField, u32)> {
    let field = |k: u32| match (k, haas) {
        (0, false) | (1, true) => ToolField::LengthWear,
        (1, false) | (0, true) => ToolField::Length,
        (2, false) | (3, true) => ToolField::RadiusWear,
        _ => ToolField::Radius,
    };
    match n {
        2001..=2800 => Some((field((n - 2001) / 200), (n - 2001) % 200 + 1)),
        // FANUC's memory C beyond 200 offsets (Haas NGC's #10000+ are its
        // common variables, not offsets).
        10001..=13999 if !haas && !n.is_multiple_of(1000) && n % 1000 <= MAX_TOOL_OFFSET => {
            Some((field(n / 1000 - 10), n % 1000))
        }
        _ => None,
    }
}

/// The work offset (`None`: external) and axis of a variable number.
fn work_variable(n: u32) -> Option<(Option<WorkSelect>, usize)> {
    match n {
        5201..=5340 => {
            let set = (n - 5201) / 20;
            let axis = ((n - 5201) % 20) as usize;
            let select = match set {
                0 => None,
                k => Some(WorkSelect::Standard(u8::try_from(k - 1).ok()?)),
            };
            Some((select, axis))
        }
        7001..=7960 => {
            let p = (n - 7001) / 20 + 1;
            Some((
                Some(WorkSelect::Extended(u8::try_from(p).ok()?)),
                ((n - 7001) % 20) as usize,
            ))
        }
        // FANUC 30i G54.1 P1 … and Haas G154 P1 … P99 alike: 20 numbers
        // an offset from #14001 (the memory holds P1 … P99).
        14001..=15980 => {
            let p = (n - 14001) / 20 + 1;
            Some((
                Some(WorkSelect::Extended(u8::try_from(p).ok()?)),
                ((n - 14001) % 20) as usize,
            ))
        }
        _ => None,
    }
}

impl Controller<'_> {
    /// Reads system variable `n`: `Ok(None)` is vacant.
    pub fn read_system_variable(&self, n: u32) -> Result<Option<f64>, SystemVarFault> {
        if let Some((field, number)) = tool_variable(n, self.dialect.haas_codes) {
            let tool = self.offsets.tools.get(&number).copied().unwrap_or_default();
            return Ok(Some(match field {
                ToolField::LengthWear => tool.length_wear,
                ToolField::Length => tool.length,
                ToolField::RadiusWear => tool.radius_wear,
                ToolField::Radius => tool.radius,
            }));
        }
        if let Some((select, axis)) = work_variable(n) {
            let Some(vector) = self.work_vector(select) else {
                return Err(SystemVarFault::Unknown);
            };
            return Ok(Some(if axis < 3 {
                vector[axis]
            } else if axis < self.machine.axis_count() {
                self.work_beyond_slot(select).map_or(0.0, |b| b[axis - 3])
            } else {
                0.0
            }));
        }
        let axes = self.machine.axis_count() as u32;
        let position = |base: u32| {
            (base + 1..=base + axes)
                .contains(&n)
                .then(|| (n - base - 1) as usize)
        };
        if let Some(i) = position(5000)
            .or_else(|| position(5040))
            .or_else(|| position(5060))
        {
            return Ok(Some(self.programmed(&self.state.joints)[i]));
        }
        if let Some(i) = position(5020) {
            return Ok(Some(self.state.joints[i]));
        }
        self.modal_variable(n).ok_or(SystemVarFault::Unknown)
    }

    /// Writes system variable `n` (tool and work offsets only).
    pub fn write_system_variable(
        &mut self,
        n: u32,
        value: Option<f64>,
    ) -> Result<(), SystemVarFault> {
        let v = value.unwrap_or(0.0);
        if let Some((field, number)) = tool_variable(n, self.dialect.haas_codes) {
            if number > MAX_TOOL_OFFSET {
                return Err(SystemVarFault::Unknown);
            }
            let tool = self.offsets.tools.entry(number).or_default();
            match field {
                ToolField::LengthWear => tool.length_wear = v,
                ToolField::Length => tool.length = v,
                ToolField::RadiusWear => tool.radius_wear = v,
                ToolField::Radius => tool.radius = v,
            }
            return Ok(());
        }
        if let Some((select, axis)) = work_variable(n) {
            if axis >= self.machine.axis_count() {
                // No such axis on this machine.
                return Err(SystemVarFault::Unknown);
            }
            if axis >= 3 {
                let slot = match select {
                    None => Some(&mut self.offsets.external_beyond),
                    Some(WorkSelect::Standard(i)) => {
                        self.offsets.work_beyond.get_mut(usize::from(i))
                    }
                    Some(WorkSelect::Extended(p) | WorkSelect::Haas(p)) => self
                        .offsets
                        .extended_work_beyond
                        .get_mut(usize::from(p).wrapping_sub(1)),
                    Some(WorkSelect::Null) => None,
                };
                let Some(slot) = slot else {
                    return Err(SystemVarFault::Unknown);
                };
                slot[axis - 3] = v;
                return Ok(());
            }
            let slot = match select {
                None => Some(&mut self.offsets.external),
                Some(WorkSelect::Standard(i)) => self.offsets.work.get_mut(usize::from(i)),
                Some(WorkSelect::Extended(p) | WorkSelect::Haas(p)) => self
                    .offsets
                    .extended_work
                    .get_mut(usize::from(p).wrapping_sub(1)),
                Some(WorkSelect::Null) => None,
            };
            let Some(slot) = slot else {
                return Err(SystemVarFault::Unknown);
            };
            slot[axis] = v;
            return Ok(());
        }
        if self.read_system_variable(n).is_ok() {
            return Err(SystemVarFault::ReadOnly);
        }
        Err(SystemVarFault::Unknown)
    }

    fn work_beyond_slot(&self, select: Option<WorkSelect>) -> Option<fiveaxis_machine::BeyondXyz> {
        match select {
            None => Some(self.offsets.external_beyond),
            Some(WorkSelect::Standard(i)) => self.offsets.work_beyond.get(usize::from(i)).copied(),
            Some(WorkSelect::Extended(p) | WorkSelect::Haas(p)) => self
                .offsets
                .extended_work_beyond
                .get(usize::from(p).wrapping_sub(1))
                .copied(),
            Some(WorkSelect::Null) => Some(fiveaxis_machine::BeyondXyz::default()),
        }
    }

    fn work_vector(&self, select: Option<WorkSelect>) -> Option<fiveaxis_machine::Vec3> {
        match select {
            None => Some(self.offsets.external),
            Some(WorkSelect::Standard(i)) => self.offsets.work.get(usize::from(i)).copied(),
            Some(WorkSelect::Extended(p) | WorkSelect::Haas(p)) => self
                .offsets
                .extended_work
                .get(usize::from(p).wrapping_sub(1))
                .copied(),
            Some(WorkSelect::Null) => Some(fiveaxis_machine::Vec3::zeros()),
        }
    }

    /// Modal information (FANUC 30i, "System variables", modal
    /// information): `#4001`–`#4030` the G code of groups 1–30 and
    /// `#4101`–`#4130` the B D E F H M N O S T P values of the blocks up
    /// to the preceding one; `#4201`–`#4230` and `#4301`–`#4330` the same
    /// of the block being executed. The kernel reads no block ahead of a
    /// macro statement, so the two are the same. `Some(None)`: a variable
    /// of the table that is vacant here (a group or address the kernel has
    /// no function of, docs/functions.md); `None`: not modal information.
    fn modal_variable(&self, n: u32) -> Option<Option<f64>> {
        match n {
            4001..=4030 => Some(self.modal_group(n - 4000)),
            4201..=4230 => Some(self.modal_group(n - 4200)),
            4101..=4130 => Some(self.modal_value(n - 4100)),
            4301..=4330 => Some(self.modal_value(n - 4300)),
            _ => None,
        }
    }

    /// The G code in force of modal group `group` (FANUC 30i-M numbering).
    fn modal_group(&self, group: u32) -> Option<f64> {
        let m = &self.state.modal;
        Some(match group {
            1 => match m.motion {
                MotionMode::Rapid => 0.0,
                MotionMode::Linear => 1.0,
                MotionMode::Cw => 2.0,
                MotionMode::Ccw => 3.0,
            },
            2 => match m.plane {
                Plane::Xy => 17.0,
                Plane::Zx => 18.0,
                Plane::Yz => 19.0,
            },
            3 => match m.distance {
                Distance::Absolute => 90.0,
                Distance::Incremental => 91.0,
            },
            // Stored stroke check 2 and 3 (barriers): the kernel has none,
            // so they are off.
            4 => 23.0,
            5 => match m.feed_mode {
                FeedMode::InverseTime => 93.0,
                FeedMode::PerMinute => 94.0,
                FeedMode::PerRevolution => 95.0,
            },
            6 => match m.units {
                Units::Inch => 20.0,
                Units::Metric => 21.0,
            },
            7 => match self.cutter.side {
                None if self.state.comp3d.active => 41.0,
                None => 40.0,
                Some(crate::cutter::Side::Left) => 41.0,
                Some(crate::cutter::Side::Right) => 42.0,
            },
            8 => match m.length {
                LengthMode::Off => 49.0,
                LengthMode::Plus => 43.0,
                LengthMode::Minus => 44.0,
                LengthMode::ToolAxis => 43.1,
                LengthMode::Tcpc(TcpcType::Angles) => 43.4,
                LengthMode::Tcpc(TcpcType::Vector) => 43.5,
            },
            9 => self
                .state
                .cycle
                .cycle
                .map_or(80.0, super::cycles::Cycle::g_number),
            10 => {
                if self.state.cycle.return_initial {
                    98.0
                } else {
                    99.0
                }
            }
            // The macro modal call (G66 / G66.1) is the runner's: it
            // answers while one is in force.
            12 => 67.0,
            // Constant surface speed is a turning function: off.
            13 => 97.0,
            14 => match m.work {
                WorkSelect::Standard(i) => 54.0 + f64::from(i),
                WorkSelect::Extended(_) => 54.1,
                WorkSelect::Haas(_) => 154.0,
                WorkSelect::Null => 500.0,
            },
            15 => match m.cutting {
                CuttingMode::ExactStop => 61.0,
                CuttingMode::CornerOverride => 62.0,
                CuttingMode::Tapping => 63.0,
                CuttingMode::Cutting => 64.0,
            },
            16 if self.feature().is_some() => 68.2,
            11 | 16 | 17 | 22 => self.state.frames.modal_g(4000 + group),
            // Normal direction control and polar coordinate interpolation:
            // functions the kernel does not have, cancelled.
            18 => 40.1,
            21 => 13.1,
            _ => return None,
        })
    }

    /// The value of address code `k` of `#4100 + k` (B 2, D 7, E 8, F 9,
    /// H 11, M 13, N 14, O 15, S 19, T 20, P 30).
    fn modal_value(&self, k: u32) -> Option<f64> {
        match k {
            7 => Some(f64::from(self.state.d)),
            9 => Some(self.state.feed),
            11 => Some(f64::from(self.state.h)),
            13 => self.state.last_m,
            14 => self.state.sequence.map(f64::from),
            19 => Some(self.state.spindle_speed),
            20 => Some(f64::from(self.state.tool)),
            30 => Some(match self.state.modal.work {
                WorkSelect::Extended(p) | WorkSelect::Haas(p) => f64::from(p),
                WorkSelect::Standard(_) | WorkSelect::Null => 0.0,
            }),
            // B (second auxiliary function) and E (thread lead): the kernel
            // has neither; O (the program number) is the runner's.
            _ => None,
        }
    }
}

impl Controller<'_> {
    /// What a number without a decimal point counts in the current program
    /// unit (least input increments: 0.001 mm, or 0.0001 inch under G20),
    /// `None` with calculator-type input (No.3401#0 DPI), where it counts
    /// in whole units. Macro call arguments of dimension addresses follow
    /// this rule.
    pub fn input_increment(&self) -> Option<f64> {
        let params = &self.machine.params;
        if params.decimal_point_input || self.dialect.calculator_input {
            None
        } else if self.state.modal.units == Units::Inch {
            Some(params.least_input_increment / 10.0)
        } else {
            Some(params.least_input_increment)
        }
    }
}
