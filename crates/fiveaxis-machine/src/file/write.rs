//! Writing a machine file that a user can copy and edit.
//!
//! Numbers are written with Rust's shortest round-trip form (`{:?}`), so
//! that [`Machine::from_toml`] reads the file back to an equal machine.

use crate::geometry::{Body, Link, Shape, Solid};
use std::collections::BTreeSet;
use std::fmt::Write as _;

use crate::{
    Along, Control, Dynamics, InputUnit, Joints, LinearAxis, Machine, MachineType,
    ProgrammingFrame, RotaryAxis, RotaryChoice, Side, Vec3,
};

/// Column at which trailing comments start, when the line is short enough.
const COMMENT_COLUMN: usize = 32;

impl Machine {
    /// This machine as a machine file (`machine-model.md` §4), with short
    /// comments on each key. [`Machine::from_toml`] reads it back to an
    /// equal machine.
    pub fn to_toml(&self) -> String {
        let mut w = Writer::default();
        w.comment("fiveaxis machine file: millimetres and degrees, machine frame.");
        w.key("name", &quote(&self.name), "shown in reports");
        w.key(
            "type",
            &quote(type_name(self.machine_type())),
            "\"head\", \"table\", \"mixed\" or \"none\": must match the rotary axes",
        );
        w.key(
            "control",
            &quote(control_name(self.control)),
            "\"fanuc30i\", \"fanuc16\", \"mitsubishi\", \"mazak\", \"haas\", \"linuxcnc\" or \"sinumerik\"",
        );
        w.key(
            "tool_direction",
            &vector(&self.tool_direction),
            "tool axis from tip to spindle, every rotary at 0",
        );
        for axis in &self.linear {
            write_linear(&mut w, axis);
        }
        for axis in &self.rotary {
            write_rotary(&mut w, axis);
        }
        self.write_parameters(&mut w);
        self.write_m_codes(&mut w);
        for body in &self.bodies {
            self.write_body(&mut w, body);
        }
        w.out
    }

    fn write_parameters(&self, w: &mut Writer) {
        let p = &self.params;
        w.blank();
        w.table(
            "[parameters]",
            "control parameters; every key may be left out",
        );
        let frame = match p.programming_frame {
            ProgrammingFrame::Table => "table",
            ProgrammingFrame::Workpiece => "workpiece",
        };
        w.key(
            "programming_frame",
            &quote(frame),
            "TCPC frame (WKP): \"table\" turns with the table, \"workpiece\" does not",
        );
        w.key(
            "tcpc_option",
            &p.tcpc_option.to_string(),
            "the control has tool centre point control",
        );
        w.key(
            "reference_1",
            &self.positions(&p.reference_1),
            "G28 position, machine coordinates; axes left out are 0",
        );
        w.key(
            "reference_2",
            &self.positions(&p.reference_2),
            "G30 position",
        );
        w.key(
            "decimal_point_input",
            &p.decimal_point_input.to_string(),
            &if p.decimal_point_input {
                "on: a number without a point is mm/degrees (X10 = 10 mm)".to_owned()
            } else {
                // As many decimals as the increment has (0.001: X10 = 0.010).
                let increment = p.least_input_increment;
                let decimals = (-increment.log10()).ceil().clamp(0.0, 9.0) as usize;
                format!(
                    "off: a number without a point is in least input increments (X10 = {:.decimals$} mm)",
                    10.0 * increment
                )
            },
        );
        w.key(
            "least_input_increment",
            &number(p.least_input_increment),
            "mm per unit of a number without a decimal point",
        );
        w.key(
            "input_unit",
            &quote(match p.input_unit {
                InputUnit::Millimetre => "mm",
                InputUnit::Inch => "inch",
            }),
            "unit until G20/G21: \"mm\" or \"inch\" (FANUC 0000#2 INI, Haas Setting 9)",
        );
        w.key(
            "tool_posture_control",
            &p.tool_posture_control.to_string(),
            "TCPC turns the tool on the great circle between block ends (FANUC 19604#0)",
        );
        let choice = match p.rotary_choice {
            RotaryChoice::Shortest => "shortest",
            RotaryChoice::RotatingAxis => "rotating_axis",
            RotaryChoice::KeepTiltSign => "keep_tilt_sign",
        };
        w.key(
            "rotary_choice",
            &quote(choice),
            "\"shortest\" total motion, \"rotating_axis\" moves least, or \"keep_tilt_sign\"",
        );
        w.key(
            "singular_zone",
            &number(p.singular_zone),
            "degrees around the singular direction where the rotating axis moves least (#7907)",
        );
        w.key(
            "tool_comp_3d_denominator",
            &number(p.tool_comp_3d_denominator),
            "p of the 3-D tool compensation vector r(i,j,k)/p; 0: the length of (i,j,k) (FANUC 5011)",
        );
        w.key(
            "cutter_startup",
            &quote(if p.cutter_startup_b { "B" } else { "A" }),
            "cutter compensation C start-up and cancel type \"A\" or \"B\" (FANUC 5003#0)",
        );
        w.key(
            "setup_error_choice",
            &quote(if p.setup_error_table_motion {
                "table_motion"
            } else {
                "keep_tilt_sign"
            }),
            "G54.4 under TCPC: \"keep_tilt_sign\" or smaller \"table_motion\" (Mazak F162 bit 1)",
        );
        w.key(
            "singular_cone",
            &number(p.singular_cone),
            "check: degrees around the singular direction reported as a singular passage",
        );
        w.key(
            "flip_angle",
            &number(p.flip_angle),
            "check: rotary turn inside one block reported as a flip, degrees",
        );
        w.key(
            "chord_tolerance",
            &number(p.chord_tolerance),
            "check: tip off the chord outside TCPC reported as a chord error, mm",
        );
        if !p.subroutine_path.is_empty() {
            let folders: Vec<String> = p.subroutine_path.iter().map(|f| quote(f)).collect();
            w.key(
                "subroutine_path",
                &format!("[{}]", folders.join(", ")),
                "folders searched for o<name> call files (LinuxCNC SUBROUTINE_PATH)",
            );
        }
        if p.tcpc_at_start {
            w.key(
                "tcpc_at_start",
                "true",
                "LinuxCNC: TCP kinematics from power-on (kinematics type 0)",
            );
        }
        if p.twp_remap {
            w.key(
                "twp_remap",
                "true",
                "LinuxCNC: the tilted-working-plane remap (G68.2 … G53.6)",
            );
        }
        if p.twp_priority != 1 {
            w.key(
                "twp_priority",
                &p.twp_priority.to_string(),
                "LinuxCNC [TWP] PRIORITY: the rotary axis the G53.x P word steers",
            );
        }
        if p.additional_common_variables != 0 {
            w.key(
                "additional_common_variables",
                &p.additional_common_variables.to_string(),
                "FANUC 30i-B additional common variables: how many of #100000… and #500000…",
            );
        }
        if let Some(table) = &p.tool_table {
            w.key(
                "tool_table",
                &quote(table),
                "LinuxCNC tool table read when no offsets file is given",
            );
        }
        if !p.hal_pins.is_empty() {
            w.blank();
            w.table(
                "[parameters.hal_pins]",
                "LinuxCNC: what a program reads as #<_hal[pin]>, the pins' values at start",
            );
            for (pin, v) in &p.hal_pins {
                w.line(&format!("{} = {}", toml_key(pin), number(*v)), "");
            }
        }
        let mut section = None;
        for (key, v) in &p.ini_values {
            let (s, name) = key.split_once(']').unwrap_or(("", key));
            if section != Some(s) {
                w.blank();
                w.line(
                    &format!("[parameters.ini.{}]", toml_key(s)),
                    if section.is_none() {
                        "LinuxCNC: what a program reads as #<_ini[section]name>"
                    } else {
                        ""
                    },
                );
                section = Some(s);
            }
            w.line(&format!("{} = {}", toml_key(name), number(*v)), "");
        }
    }

    fn write_m_codes(&self, w: &mut Writer) {
        w.blank();
        w.table(
            "[m_codes]",
            "the builder's M codes: number = function; each replaces the control's meaning",
        );
        if self.m_codes.is_empty() {
            w.comment("e.g. 10 = \"clamp A\", 29 = \"rigid_tap\", 50 = \"signal\"");
        }
        for (number, function) in self.m_codes.iter() {
            w.line(&format!("{number} = {}", quote(&function.to_string())), "");
        }
    }

    /// A reference position as an inline table over every axis.
    fn write_body(&self, w: &mut Writer, body: &Body) {
        w.blank();
        w.table(
            "[[body]]",
            "a solid part of the machine: the union of its solids, which move with `on`",
        );
        w.key("name", &quote(&body.name), "named in collision findings");
        let on = match body.on {
            Link::Base => "base".to_owned(),
            Link::Head => "head".to_owned(),
            Link::Axis(i) => self
                .axis_names()
                .nth(i)
                .map_or_else(String::new, String::from),
        };
        w.key(
            "on",
            &quote(&on),
            "\"base\", \"head\", X, Y, Z or a rotary axis; coordinates: machine frame, every axis at 0",
        );
        w.line("solids = [", "");
        for solid in &body.solids {
            w.line(&format!("    {},", solid_text(solid, &self.meshes)), "");
        }
        w.line("]", "");
    }

    fn positions(&self, joints: &Joints) -> String {
        let items: Vec<String> = self
            .axis_names()
            .zip(joints)
            .map(|(name, v)| format!("{name} = {}", number(*v)))
            .collect();
        format!("{{ {} }}", items.join(", "))
    }
}

fn write_linear(w: &mut Writer, axis: &LinearAxis) {
    w.blank();
    w.table(
        "[[linear]]",
        "a linear axis: X, Y, Z first, then U, V or W (parallel to X, Y, Z)",
    );
    w.key("name", &quote(&axis.name.to_string()), "");
    w.key("min", &number(axis.min), "lower soft limit, mm");
    w.key("max", &number(axis.max), "upper soft limit, mm");
    if axis.along == Along::Tool {
        w.key(
            "along",
            &quote("tool"),
            "a quill: moves the tip along the tool, + away from the work",
        );
    }
    write_dynamics(w, &axis.dynamics, "mm");
}

fn write_dynamics(w: &mut Writer, d: &Dynamics, unit: &str) {
    w.key(
        "max_velocity",
        &number(d.max_velocity),
        &format!("fastest cutting feed, {unit}/min (FANUC No.1430)"),
    );
    w.key(
        "rapid",
        &number(d.rapid),
        &format!("rapid traverse rate, {unit}/min (FANUC No.1420)"),
    );
    w.key(
        "max_acceleration",
        &number(d.max_acceleration),
        &format!("{unit}/s^2 (FANUC No.1660)"),
    );
    match d.max_jerk {
        Some(jerk) => w.key("max_jerk", &number(jerk), &format!("{unit}/s^3, optional")),
        None => w.comment("No max_jerk: jerk not limited."),
    }
}

fn write_rotary(w: &mut Writer, axis: &RotaryAxis) {
    w.blank();
    w.table("[[rotary]]", "a rotary axis, listed from the bed outwards");
    w.key("name", &quote(&axis.name.to_string()), "A, B or C");
    let on = match axis.on {
        Side::Head => "head",
        Side::Table => "table",
    };
    w.key(
        "on",
        &quote(on),
        "\"head\" turns the spindle, \"table\" the workpiece",
    );
    w.key(
        "axis",
        &vector(&axis.axis),
        "rotation line direction; +angle turns the carried part right-handed",
    );
    w.key(
        "center",
        &vector(&axis.center),
        "a point on the line (head: from the gauge point)",
    );
    if let Some((min, max)) = axis.limits {
        w.key("min", &number(min), "lower soft limit, degrees");
        w.key("max", &number(max), "upper soft limit, degrees");
    } else if !axis.rollover {
        w.comment("No min/max: this axis has no soft limits.");
    }
    w.key(
        "rollover",
        &axis.rollover.to_string(),
        "endless axis shown modulo 360 (then no min/max)",
    );
    write_dynamics(w, &axis.dynamics, "deg");
}

/// Builds the text; comments a key only the first time it appears in a
/// kind of table, so repeated tables stay short.
#[derive(Default)]
struct Writer {
    out: String,
    table: &'static str,
    commented: BTreeSet<(&'static str, &'static str)>,
}

impl Writer {
    fn blank(&mut self) {
        self.out.push('\n');
    }

    fn comment(&mut self, text: &str) {
        let _ = writeln!(self.out, "# {text}");
    }

    fn table(&mut self, header: &'static str, comment: &str) {
        let first = self.commented.insert((header, ""));
        self.table = header;
        self.line(header, if first { comment } else { "" });
    }

    fn key(&mut self, key: &'static str, value: &str, comment: &str) {
        let first = self.commented.insert((self.table, key));
        self.line(
            &format!("{key} = {value}"),
            if first { comment } else { "" },
        );
    }

    fn line(&mut self, text: &str, comment: &str) {
        if comment.is_empty() {
            let _ = writeln!(self.out, "{text}");
        } else {
            let pad = COMMENT_COLUMN.saturating_sub(text.chars().count()).max(1);
            let _ = writeln!(self.out, "{text}{:pad$}# {comment}", "");
        }
    }
}

/// A number that reads back to the same bits.
/// A solid as an inline table (`file/bodies.rs` reads it back).
fn solid_text(solid: &Solid, meshes: &[crate::geometry::BodyMesh]) -> String {
    let shape = match solid.shape {
        Shape::Box { size } => format!("box = {}", vector(&size)),
        Shape::Cylinder { radius, length } => {
            format!("cylinder = [{}, {}]", number(radius), number(length))
        }
        Shape::Cone {
            bottom,
            top,
            length,
        } => format!(
            "cone = [{}, {}, {}]",
            number(bottom),
            number(top),
            number(length)
        ),
        Shape::Sphere { radius } => format!("sphere = {}", number(radius)),
        Shape::Capsule { radius, length } => {
            format!("capsule = [{}, {}]", number(radius), number(length))
        }
        Shape::Mesh { mesh } => format!(
            "mesh = {}",
            toml::Value::String(meshes.get(mesh).map_or(String::new(), |m| m.file.clone()))
        ),
    };
    let p = &solid.place;
    let mut text = format!("{{ {shape}, at = {}", vector(&p.at));
    if p.axis.into_inner() != Vec3::z() {
        text.push_str(&format!(", axis = {}", vector(&p.axis)));
    }
    if p.turn != 0.0 {
        text.push_str(&format!(", turn = {}", number(p.turn)));
    }
    text.push_str(" }");
    text
}

fn number(v: f64) -> String {
    format!("{v:?}")
}

fn vector(v: &Vec3) -> String {
    format!("[{}, {}, {}]", number(v.x), number(v.y), number(v.z))
}

/// A TOML key: bare when it can be, else quoted.
fn toml_key(s: &str) -> String {
    let bare = !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if bare { s.to_owned() } else { quote(s) }
}

/// A TOML string, escaped as needed.
fn quote(s: &str) -> String {
    toml::Value::String(s.to_owned()).to_string()
}

fn type_name(t: MachineType) -> &'static str {
    match t {
        MachineType::None => "none",
        MachineType::Head => "head",
        MachineType::Table => "table",
        MachineType::Mixed => "mixed",
    }
}

fn control_name(c: Control) -> &'static str {
    match c {
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
