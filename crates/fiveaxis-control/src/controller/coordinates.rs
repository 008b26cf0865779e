//! The coordinate chain: how a programmed point becomes a point of the
//! table frame, in the order the control applies the stages (each stage
//! in one place):
//!
//! 1. **Program transforms** (`program_transforms.rs`): polar coordinates
//!    G16, programmable mirror image G51.1, scaling G51, coordinate
//!    rotation G68 in the plane (the manual's order), read on the program's
//!    own coordinates.
//! 2. **Feature frame** (`feature_frame.rs`): the tilted working plane
//!    (G68.2 and its forms, G68.3, G68.4) or a three-dimensional
//!    coordinate conversion (G68 with I J K): `origin + R·p`; LinuxCNC's
//!    TWP remap (`twp.rs`) puts its plane here from G53.x on.
//! 3. **Local shifts**: the G52 local coordinate system and the 3-D tool
//!    compensation vector ([`Controller::local_vector`]).
//! 4. **Setup error** (`setup_error.rs`): G54.4 maps the ideal workpiece
//!    onto the real one about the work zero.
//! 5. **Work offset** ([`Controller::work`]): G54–G59 / G54.1 P, the
//!    external offset and the G92 shift ([`Controller::set_coordinate_system`]).
//!
//! [`Controller::to_real`] composes 2 to 5 (stage 1 acts on the block's
//! end point before, in `end_point`), [`Controller::programmed_of_real`]
//! is its inverse. Under TCPC the programming frame is the table's (or
//! the workpiece frame that does not turn, WKP = 1), through the feature
//! frame when one is in force (`feature_isometry`, used by `tcpc.rs`).
//! The tool length is added after the chain (`length_vector`), along the
//! tool in the feature frame.

use fiveaxis_machine::{Joints, Vec3};

use super::Controller;
use crate::alarm::Alarm;
use crate::modal::WorkSelect;

mod feature_frame;
mod program_transforms;
mod setup_error;
mod twp;

pub(super) use feature_frame::{Feature, Pending};
pub(super) use program_transforms::Frames;
pub(crate) use program_transforms::{MIRROR, POLAR, ROTATION, SCALING};

impl Controller<'_> {
    /// The active work offset W plus G92 and external shifts.
    pub(super) fn work(&self) -> Vec3 {
        let base = match self.state.modal.work {
            WorkSelect::Standard(i) => self.offsets.work[usize::from(i)],
            WorkSelect::Extended(p) | WorkSelect::Haas(p) => {
                self.offsets.extended_work[usize::from(p) - 1]
            }
            WorkSelect::Null => Vec3::zeros(),
        };
        base + self.offsets.external + self.state.shift
    }

    /// The work offset of axis `i` beyond X, Y, Z (joint index, 3 or
    /// more) in force: the selected work offset's value for that axis and
    /// the external offset's (FANUC keeps one value per controlled axis;
    /// `#5224`…, the offsets file's fourth value on).
    pub(super) fn work_beyond(&self, i: usize) -> f64 {
        let k = i - 3;
        let base = match self.state.modal.work {
            WorkSelect::Standard(s) => self.offsets.work_beyond[usize::from(s)][k],
            WorkSelect::Extended(p) | WorkSelect::Haas(p) => {
                self.offsets.extended_work_beyond[usize::from(p) - 1][k]
            }
            WorkSelect::Null => 0.0,
        };
        base + self.offsets.external_beyond[k]
    }

    /// A programmed point (after the program transforms) as a point of
    /// the real workpiece in the table frame at table position 0: stages 2
    /// to 5 of the chain (feature frame, local shifts, setup error, work
    /// offset).
    pub(super) fn to_real(&self, p: &Vec3) -> Vec3 {
        self.work()
            + self
                .state
                .setup
                .point(&(self.feature_to_work(p) + self.local_vector()))
    }

    /// The inverse of [`Controller::to_real`]: a real point as programmed.
    pub(super) fn programmed_of_real(&self, x: &Vec3) -> Vec3 {
        self.work_to_feature(
            &(self.state.setup.inverse_point(&(x - self.work())) - self.local_vector()),
        )
    }

    /// What is added to a programmed point before the setup error: the
    /// 3-D compensation vector and the G52 local coordinate system.
    pub(super) fn local_vector(&self) -> Vec3 {
        self.state.comp3d.vector + self.state.frames.local
    }

    /// G92: the current position gets the named coordinates (all work
    /// coordinate systems shift).
    pub(super) fn set_coordinate_system(&mut self, from: &Joints) -> Result<(), Alarm> {
        let rules = self.rules();
        for (i, value) in self.fanuc.axis_values(&rules).into_iter().enumerate() {
            if let Some(value) = value {
                if i < 3 {
                    // G92 cancels the local coordinate system of its axes.
                    self.state.shift[i] += from[i] - value + self.state.frames.local[i];
                    self.state.frames.local[i] = 0.0;
                } else {
                    self.state.axis_shift[i] += from[i] - value;
                }
            }
        }
        Ok(())
    }
}
