//! The plain block: a straight move written with axis words, F and at
//! most G00 / G01, in a state where no function is in force that such a
//! block could start, end or pass through (no canned cycle, 3-D tool
//! compensation, tilted plane or dynamic work offset, LinuxCNC motion
//! mode, TCP kinematics still to switch on). TCPC and cutter
//! compensation C may be in force: the motion itself takes them into
//! account. Most blocks of CAM output are such blocks.
//!
//! [`Controller::execute_plain`] runs them through the same functions as
//! the general path (axis words, feed, end point, machine position,
//! segment, clamps and soft limits) and leaves out only the passes that
//! the conditions of [`Controller::plain_block`] prove have nothing to
//! do: G-code classification beyond the motion code, M codes, length
//! offset, compensations, frames, features, cycles. On an alarm the
//! state is put back as it was before the block, as on the general path
//! (which copies the whole state; the plain path saves the part it may
//! change, [`Undo`]).
//!
//! Invariant: for every block and state, the plain path gives the same
//! segments, flow, alarm and state as the general path (tested block for
//! block on random programs in `tests/no_panic.rs`).

use fiveaxis_gcode::Code;
use fiveaxis_machine::Vec3;

use super::{Controller, Flow};
use crate::alarm::Alarm;
use crate::fanuc::Words;
use crate::modal::{MotionMode, TcpcType};
use crate::segment::Segment;

/// G00 and G01.
const RAPID: Code = Code::new(0, 0);
const LINEAR: Code = Code::new(1, 0);

/// What of the state a plain block may change (its motion code, F, the
/// position and what the motion functions keep: cutter compensation C
/// the position, TCPC its vector and angles, the setup error that follows
/// the rotary axes), to put back on an alarm as the general path puts
/// back its copy of the whole state. Outside TCPC a plain block changes
/// nothing of TCPC's but its start-up flag, so the rest is saved only
/// while TCPC is in force. Tests check,
/// with debug assertions on, that the state put back equals the whole.
struct Undo {
    motion: MotionMode,
    cycle: super::cycles::CycleState,
    feed: f64,
    sequence: Option<u32>,
    joints: fiveaxis_machine::Joints,
    setup: fiveaxis_machine::SetupError,
    tcpc_startup: bool,
    tcpc: Option<TcpcUndo>,
}

/// What TCPC motion may change.
struct TcpcUndo {
    tcpc: super::tcpc::TcpcState,
    setup_angles: Option<[f64; 2]>,
}

impl Undo {
    fn of(state: &super::State, tcpc_in_force: bool) -> Self {
        Self {
            motion: state.modal.motion,
            cycle: state.cycle,
            feed: state.feed,
            sequence: state.sequence,
            joints: state.joints,
            setup: state.setup,
            tcpc_startup: state.tcpc.startup,
            // Copied only when needed (TCPC's state is large).
            tcpc: if tcpc_in_force {
                Some(TcpcUndo {
                    tcpc: state.tcpc,
                    setup_angles: state.setup_angles,
                })
            } else {
                None
            },
        }
    }

    fn put_back(self, state: &mut super::State) {
        state.modal.motion = self.motion;
        state.cycle = self.cycle;
        state.feed = self.feed;
        state.sequence = self.sequence;
        state.joints = self.joints;
        state.setup = self.setup;
        if let Some(saved) = self.tcpc {
            state.tcpc = saved.tcpc;
            state.setup_angles = saved.setup_angles;
        }
        state.tcpc.startup = self.tcpc_startup;
    }
}

impl Controller<'_> {
    /// Whether the block just loaded is a plain block in a plain state,
    /// and its motion code if it has one: `Some(None)` a plain block
    /// without G code, `Some(Some(mode))` one with G00 or G01, `None` a
    /// block for the general path.
    pub(super) fn plain_block(&self) -> Option<Option<MotionMode>> {
        if !self.plain_path || self.operands.active {
            return None;
        }
        // Under TCPC type 2, I, J, K give the tool direction of the move.
        let addresses = if self.tcpc_type() == Some(TcpcType::Vector) {
            self.plain_addresses | Words::letter_mask(*b"IJK")
        } else {
            self.plain_addresses
        };
        let code = self.fanuc.plain_motion_code(addresses)?;
        let mode = match code {
            None => None,
            Some(RAPID) => Some(MotionMode::Rapid),
            Some(LINEAR) => Some(MotionMode::Linear),
            Some(_) => return None,
        };
        let state = &self.state;
        let plain_state =
            code.is_some() || matches!(state.modal.motion, MotionMode::Rapid | MotionMode::Linear);
        let plain_state = plain_state
            && state.cycle.cycle.is_none()
            && state.ngc_motion.is_none()
            && state.spline_tangent.is_none()
            && state.feature.is_none()
            && state.feature_pending.is_none()
            && state.setup_angles.is_none()
            && !state.kinematics_pending
            && !state.comp3d.active
            && state.comp3d.vector == Vec3::zeros();
        plain_state.then_some(mode)
    }

    /// Executes a block [`Controller::plain_block`] admitted, with motion
    /// code `mode`.
    pub(super) fn execute_plain(
        &mut self,
        mode: Option<MotionMode>,
        sequence: Option<u32>,
        base: usize,
        out: &mut Vec<Segment>,
    ) -> Result<Flow, Alarm> {
        let undo = Undo::of(&self.state, self.tcpc_type().is_some());
        #[cfg(debug_assertions)]
        let whole = self.state;
        if let Some(n) = sequence {
            self.state.sequence = Some(n);
        }
        let result = self.plain_motion(mode, base, out);
        if result.is_err() {
            undo.put_back(&mut self.state);
            out.truncate(base);
            // The parts saved are all the plain path changes.
            #[cfg(debug_assertions)]
            debug_assert_eq!(format!("{:?}", self.state), format!("{whole:?}"));
        }
        result.map(|()| Flow::Next)
    }

    /// The general path's steps that act on a plain block, in its order.
    fn plain_motion(
        &mut self,
        mode: Option<MotionMode>,
        base: usize,
        out: &mut Vec<Segment>,
    ) -> Result<(), Alarm> {
        self.block_exact_stop = self.pending_exact_stop;
        self.block_chose_rotary.set(false);
        if let Some(mode) = mode {
            // Group 01 (apply_modal), which also cancels a canned cycle.
            self.state.modal.motion = mode;
            self.state.cycle.cancel();
        }
        self.refresh_xy_rotation();
        self.apply_values(false)?;
        let from = if self.cutter.routing() {
            // Cutter compensation C holds blocks back: the program stands
            // at the end of the last block read.
            self.cutter.point
        } else {
            self.programmed(&self.state.joints)
        };
        // No length code or H: the offset stays (apply_length).
        self.state.tcpc.startup = false;
        // No G41 / G42 / G40 (apply_cutter).
        self.cutter.vector = None;
        self.motion(&from, false, out)?;
        self.end_block(base, out)
    }

    /// Sends every block through the general path (off) or plain blocks
    /// through the plain path (on, the default): for the tests that
    /// compare the two.
    pub fn set_plain_path(&mut self, on: bool) {
        self.plain_path = on;
    }
}
