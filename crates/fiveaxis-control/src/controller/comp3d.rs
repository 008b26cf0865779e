//! Three-dimensional tool compensation (FANUC Series 16/18-C, seed 001):
//! G41 / G42 with all of I, J, K.
//!
//! At the end of every block the tool is shifted by the vector
//! `V = r·(i, j, k)/p` (G42: `−V`), r the D offset, p the length of
//! (i, j, k) or parameter No.5011 when it is set, so that one program
//! (surface points with their normals) serves every cutter size. Blocks
//! without I, J, K and arc blocks keep the vector of the block before;
//! G28 / G30 clear it at their intermediate point; G40 cancels it. The
//! vector is added to the programmed point before the work offset and the
//! tool length compensation, in the programming frame, so on a 5-axis
//! machine (and under TCPC, evaluated at block ends as the FANUC 15i
//! manual describes) the compensated point goes through the same
//! kinematics.

use fiveaxis_machine::Vec3;

use super::Controller;
use crate::alarm::Alarm;
use crate::command::CutterSide;
use crate::fanuc::GCodes;
use crate::modal::{MotionMode, TcpcType};

/// 3-D tool compensation state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Comp3d {
    /// The mode is on (G41 / G42 with I, J, K).
    pub(super) active: bool,
    /// +1 for G41, −1 for G42.
    sign: f64,
    /// The last programmed (i, j, k), mm.
    ijk: Vec3,
    /// The offset vector at the current position, programming frame.
    pub(super) vector: Vec3,
}

impl Controller<'_> {
    /// Whether a G41 / G42 block starts 3-D tool compensation (it gives all
    /// of I, J, K and is not an arc) rather than cutter compensation C.
    pub(super) fn starts_comp3d(&self, codes: &GCodes) -> bool {
        let arc = matches!(self.state.modal.motion, MotionMode::Cw | MotionMode::Ccw);
        matches!(
            codes.cutter,
            Some((CutterSide::Left | CutterSide::Right, _))
        ) && !arc
            && self.fanuc.has_whole_vector()
    }

    /// Group 07 for 3-D tool compensation and the vector at the end of this
    /// block. Returns whether the vector changed (the axes then move by
    /// the change even without axis words).
    pub(super) fn apply_comp3d(&mut self, codes: &GCodes) -> Result<bool, Alarm> {
        let before = self.state.comp3d.vector;
        let arc = matches!(self.state.modal.motion, MotionMode::Cw | MotionMode::Ccw);
        if self.starts_comp3d(codes) {
            self.check_comp3d_startup()?;
            let sign = if codes
                .cutter
                .is_some_and(|(side, _)| side == CutterSide::Left)
            {
                1.0
            } else {
                -1.0
            };
            self.state.comp3d = Comp3d {
                active: true,
                sign,
                ijk: self.read_ijk(),
                vector: before,
            };
        } else if codes
            .cutter
            .is_some_and(|(side, _)| side == CutterSide::Off)
        {
            self.state.comp3d = Comp3d::default();
        } else if self.state.comp3d.active
            && !arc
            && self.tcpc_type() != Some(TcpcType::Vector)
            && self.fanuc.has_vector()
        {
            // In the mode, I, J, K give the vector of this block end (an
            // omitted one counts 0). Arcs keep the vector: their I, J, K are
            // the centre.
            self.state.comp3d.ijk = self.read_ijk();
        }
        let comp = self.state.comp3d;
        let vector = if !comp.active {
            Vec3::zeros()
        } else if arc {
            before
        } else {
            // I, J, K are programmed coordinates: in a tilted plane (G68.2)
            // or a 3-D coordinate conversion, those of the feature frame;
            // the vector is kept in the work coordinate system.
            let v = comp.sign * self.tool_radius() * comp.ijk / self.comp3d_denominator(&comp.ijk);
            self.feature_vector(&v)
        };
        self.state.comp3d.vector = vector;
        Ok(vector != before)
    }

    /// P/S 047 and 048 at start-up: two axes in the same direction, or an
    /// omitted axis whose basic axis the machine does not have.
    fn check_comp3d_startup(&self) -> Result<(), Alarm> {
        let machine = self.machine;
        self.fanuc
            .comp3d_startup_axes(|name| machine.axis_index(name).is_some())
    }

    /// I, J, K of the block (an omitted one is 0), taken.
    fn read_ijk(&mut self) -> Vec3 {
        let rules = self.rules();
        Vec3::from(self.fanuc.vector(&rules))
    }

    /// p of the vector: parameter No.5011, or the length of (i, j, k).
    fn comp3d_denominator(&self, ijk: &Vec3) -> f64 {
        let p = self.machine.params.tool_comp_3d_denominator;
        let p = if p > 0.0 { p } else { ijk.norm() };
        if p > 0.0 { p } else { f64::INFINITY }
    }

    /// The active D value (geometry + wear), mm.
    pub(super) fn tool_radius(&self) -> f64 {
        let tool = self.offsets.tool(self.state.d);
        tool.radius + tool.radius_wear + self.state.tool_delta[1]
    }
}
