//! `fiveaxis._native.Machine`: an immutable machine description, built in,
//! from a machine file or from TOML text, with its axes, limits and
//! parameters readable.

use std::path::PathBuf;

use fiveaxis_machine::{
    Control, Dynamics, InputUnit, Machine, MachineType, ProgrammingFrame, RotaryChoice, Side,
    builtin, builtin_names,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{file_error, invalid};
use crate::inputs::read_data_file;

/// A machine.
#[pyclass(name = "Machine", module = "fiveaxis._native", frozen)]
#[derive(Debug)]
pub struct PyMachine {
    pub machine: Machine,
}

fn control_name(control: Control) -> &'static str {
    match control {
        Control::Fanuc30i => "fanuc30i",
        Control::Fanuc16 => "fanuc16",
        Control::Mitsubishi => "mitsubishi",
        Control::Mazak => "mazak",
        Control::Haas => "haas",
        Control::LinuxCnc => "linuxcnc",
        Control::Sinumerik => "sinumerik",
        Control::Heidenhain => "heidenhain",
    }
}

fn dynamics<'py>(py: Python<'py>, d: &Dynamics) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("max_velocity", d.max_velocity)?;
    out.set_item("rapid", d.rapid)?;
    out.set_item("max_acceleration", d.max_acceleration)?;
    out.set_item("max_jerk", d.max_jerk)?;
    Ok(out)
}

fn triple(v: &fiveaxis_machine::Vec3) -> (f64, f64, f64) {
    (v.x, v.y, v.z)
}

#[pymethods]
impl PyMachine {
    /// A built-in machine by name.
    #[staticmethod]
    fn builtin(py: Python<'_>, name: &str) -> PyResult<Self> {
        builtin(name)
            .map(|machine| Self { machine })
            .ok_or_else(|| {
                invalid(
                    py,
                    format!(
                        "`{name}` is not a built-in machine; built-in machines: {}",
                        builtin_names().join(", ")
                    ),
                )
            })
    }

    /// A machine from the text of a machine file; `file` names it in
    /// errors.
    #[staticmethod]
    #[pyo3(signature = (text, file = "<string>"))]
    fn from_toml(py: Python<'_>, text: &str, file: &str) -> PyResult<Self> {
        Machine::from_toml(text)
            .map(|machine| Self { machine })
            .map_err(|e| file_error(py, file, &e))
    }

    /// A machine from a machine file.
    #[staticmethod]
    fn from_file(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let text = read_data_file(py, &path)?;
        Machine::from_toml(&text)
            .map(|machine| Self { machine })
            .map_err(|e| file_error(py, &path.display().to_string(), &e))
    }

    /// The machine's name.
    #[getter]
    fn name(&self) -> String {
        self.machine.name.clone()
    }

    /// The control family.
    #[getter]
    fn control(&self) -> &'static str {
        control_name(self.machine.control)
    }

    /// The machine type: `none`, `head`, `table` or `mixed`.
    #[getter]
    fn machine_type(&self) -> &'static str {
        match self.machine.machine_type() {
            MachineType::None => "none",
            MachineType::Head => "head",
            MachineType::Table => "table",
            MachineType::Mixed => "mixed",
        }
    }

    /// Axis names, in the order of the position columns.
    #[getter]
    fn axes(&self) -> Vec<String> {
        self.machine.axis_names().map(String::from).collect()
    }

    /// Tool direction (tip to spindle) with every rotary axis at 0.
    #[getter]
    fn tool_direction(&self) -> (f64, f64, f64) {
        triple(&self.machine.tool_direction)
    }

    /// The linear axes: name, soft limits and dynamics.
    #[getter]
    fn linear_axes<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.machine
            .linear
            .iter()
            .map(|a| {
                let d = PyDict::new(py);
                d.set_item("name", a.name.to_string())?;
                d.set_item("min", a.min)?;
                d.set_item("max", a.max)?;
                d.set_item("dynamics", dynamics(py, &a.dynamics)?)?;
                Ok(d)
            })
            .collect()
    }

    /// The rotary axes, bed outwards: name, side, rotation line, soft
    /// limits (`None`: none), rollover and dynamics.
    #[getter]
    fn rotary_axes<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.machine
            .rotary
            .iter()
            .map(|a| {
                let d = PyDict::new(py);
                d.set_item("name", a.name.to_string())?;
                d.set_item(
                    "on",
                    match a.on {
                        Side::Head => "head",
                        Side::Table => "table",
                    },
                )?;
                d.set_item("axis", triple(&a.axis))?;
                d.set_item("center", triple(&a.center))?;
                d.set_item("limits", a.limits)?;
                d.set_item("rollover", a.rollover)?;
                d.set_item("dynamics", dynamics(py, &a.dynamics)?)?;
                Ok(d)
            })
            .collect()
    }

    /// The control parameters, by their machine-file names.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = &self.machine.params;
        let n = self.machine.axis_count();
        let d = PyDict::new(py);
        d.set_item(
            "programming_frame",
            match p.programming_frame {
                ProgrammingFrame::Table => "table",
                ProgrammingFrame::Workpiece => "workpiece",
            },
        )?;
        d.set_item("tcpc_option", p.tcpc_option)?;
        d.set_item("reference_1", p.reference_1[..n].to_vec())?;
        d.set_item("reference_2", p.reference_2[..n].to_vec())?;
        d.set_item("decimal_point_input", p.decimal_point_input)?;
        d.set_item("least_input_increment", p.least_input_increment)?;
        d.set_item(
            "input_unit",
            match p.input_unit {
                InputUnit::Millimetre => "mm",
                InputUnit::Inch => "inch",
            },
        )?;
        d.set_item("tool_posture_control", p.tool_posture_control)?;
        d.set_item(
            "rotary_choice",
            match p.rotary_choice {
                RotaryChoice::Shortest => "shortest",
                RotaryChoice::RotatingAxis => "rotating_axis",
                RotaryChoice::KeepTiltSign => "keep_tilt_sign",
            },
        )?;
        d.set_item("singular_zone", p.singular_zone)?;
        d.set_item("tool_comp_3d_denominator", p.tool_comp_3d_denominator)?;
        d.set_item("cutter_startup_b", p.cutter_startup_b)?;
        d.set_item("setup_error_table_motion", p.setup_error_table_motion)?;
        d.set_item("singular_cone", p.singular_cone)?;
        d.set_item("flip_angle", p.flip_angle)?;
        d.set_item("chord_tolerance", p.chord_tolerance)?;
        Ok(d)
    }

    /// The machine as a machine file (TOML).
    fn to_toml(&self) -> String {
        self.machine.to_toml()
    }

    fn __repr__(&self) -> String {
        format!(
            "Machine({:?}, axes={})",
            self.machine.name,
            self.machine.axis_names().collect::<String>()
        )
    }
}
