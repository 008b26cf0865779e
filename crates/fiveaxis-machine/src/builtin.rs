//! The built-in machine library: one machine of each type, so that the
//! program runs with no machine file. Each is kept as machine-file text and
//! read with [`Machine::from_toml`], so the library also exercises the
//! file format.
//!
//! The FANUC 30i machines: `trunnion-ac` (the default), `trunnion-bc`,
//! `head-table-bc`, `head-head-ca`, `mill-3axis`. Haas: `haas-umc750`,
//! `haas-vf2-tr160`. SINUMERIK: `sinumerik-dmu-bc`, a 45° swivel head B
//! with a rotary table C, also kept as the swivel data record
//! (`$TC_CARR`, kinematic type M) that
//! [`import_tc_carr`](crate::import_tc_carr) turns into the same machine
//! (`data/sinumerik-dmu-bc.spf`).
//!
//! Every built-in machine has a plausible set of bodies (`[[body]]`: bed,
//! table, cradle, spindle head; `geometry.rs`), assumed from the size of
//! its travels, not a maker's figures.

use crate::Machine;

/// Name of the machine used when none is given.
pub const DEFAULT_MACHINE: &str = "trunnion-ac";

/// What every built-in FANUC machine shares besides its axes: the
/// reference positions at the top of Z travel (see `linear_axes`), and
/// FANUC's usual M codes M00–M09, M19, M29 rigid tapping (FANUC No.5210
/// commonly 29) and M30.
macro_rules! standard_m_codes {
    () => {
        r#"
[parameters]
reference_1 = { Z = 500.0 }
reference_2 = { Z = 500.0 }

[m_codes]
0 = "stop"
1 = "optional_stop"
2 = "end"
3 = "spindle_cw"
4 = "spindle_ccw"
5 = "spindle_stop"
6 = "tool_change"
7 = "coolant_on"
8 = "coolant_on"
9 = "coolant_off"
19 = "spindle_orient"
29 = "rigid_tap"
30 = "end"
"#
    };
}

/// Linear axes of the built-in FANUC machines, the size of a mid-size
/// five-axis machining centre. Machine zero lies on the C axis line in
/// the face of the table (the table frame of the machine-model contract
/// starts there, so a work offset is measured from the table's centre and
/// face); the first and second reference positions (FANUC No.1240,
/// No.1241: the machine coordinates of the reference positions) are at
/// the top of Z travel, where the spindle nose stands 500 mm above the
/// table face and a program starts. Z travels 800 mm (Z 500 down to
/// −300): below the table face the spindle reaches the sides of a tilted
/// part, and a swivel head turned horizontal (its pivot 150 mm above the
/// gauge point) cuts down to the table face. X 1000 mm and Y 800 mm
/// centred on the table. Dynamics are typical
/// catalogue figures: 30 m/min rapid (FANUC No.1420), 20 m/min cutting
/// feed (No.1430), 3 m/s² (about 0.3 g, No.1660), the acceleration reached
/// in 60 ms (jerk 50 m/s³).
macro_rules! linear_axes {
    () => {
        r#"
[[linear]]
name = "X"
min = -500.0
max = 500.0
max_velocity = 20000.0
rapid = 30000.0
max_acceleration = 3000.0
max_jerk = 50000.0

[[linear]]
name = "Y"
min = -400.0
max = 400.0
max_velocity = 20000.0
rapid = 30000.0
max_acceleration = 3000.0
max_jerk = 50000.0

[[linear]]
name = "Z"
min = -300.0
max = 500.0
max_velocity = 20000.0
rapid = 30000.0
max_acceleration = 3000.0
max_jerk = 50000.0
"#
    };
}

/// Plausible bodies of the built-in trunnion machines, assumed, not a
/// maker's figures: a bed 510 mm below the table face with two supports
/// carrying the tilt axis (100 mm below the face, as its `center`), a
/// cradle on the tilt axis (a 40 mm plate under the table and two walls
/// at its ends, rising to the table face), a round table Ø500 × 40 on the
/// turning axis, and a spindle housing Ø180 rising from the gauge point.
/// `$tilt` names the tilt axis, `$along` the machine axis it lies along.
macro_rules! trunnion_bodies {
    ("A", "x") => {
        r#"
[[body]]
name = "bed"
on = "base"
solids = [
    { box = [1200.0, 1000.0, 100.0], at = [0.0, 0.0, -560.0] },
    { box = [100.0, 400.0, 450.0], at = [-460.0, 0.0, -285.0] },
    { box = [100.0, 400.0, 450.0], at = [460.0, 0.0, -285.0] },
]

[[body]]
name = "cradle"
on = "A"
solids = [
    { box = [780.0, 560.0, 40.0], at = [0.0, 0.0, -80.0] },
    { box = [40.0, 560.0, 100.0], at = [-370.0, 0.0, -50.0] },
    { box = [40.0, 560.0, 100.0], at = [370.0, 0.0, -50.0] },
]

[[body]]
name = "table"
on = "C"
solids = [{ cylinder = [250.0, 40.0], at = [0.0, 0.0, -40.0] }]

[[body]]
name = "head"
on = "head"
solids = [{ cylinder = [90.0, 450.0], at = [0.0, 0.0, 0.0] }]
"#
    };
    ("B", "y") => {
        r#"
[[body]]
name = "bed"
on = "base"
solids = [
    { box = [1200.0, 1000.0, 100.0], at = [0.0, 0.0, -560.0] },
    { box = [400.0, 100.0, 450.0], at = [0.0, -460.0, -285.0] },
    { box = [400.0, 100.0, 450.0], at = [0.0, 460.0, -285.0] },
]

[[body]]
name = "cradle"
on = "B"
solids = [
    { box = [560.0, 780.0, 40.0], at = [0.0, 0.0, -80.0] },
    { box = [560.0, 40.0, 100.0], at = [0.0, -370.0, -50.0] },
    { box = [560.0, 40.0, 100.0], at = [0.0, 370.0, -50.0] },
]

[[body]]
name = "table"
on = "C"
solids = [{ cylinder = [250.0, 40.0], at = [0.0, 0.0, -40.0] }]

[[body]]
name = "head"
on = "head"
solids = [{ cylinder = [90.0, 450.0], at = [0.0, 0.0, 0.0] }]
"#
    };
}

/// Plausible bodies of `head-table-bc`, assumed: a bed under a round table
/// Ø600 × 60 on C, the spindle Ø140 from the gauge point up to the B
/// pivot (150 mm above it) and the swivel housing Ø220 along the B axis.
macro_rules! head_table_bodies {
    () => {
        r#"
[[body]]
name = "bed"
on = "base"
solids = [{ box = [1200.0, 1000.0, 100.0], at = [0.0, 0.0, -111.0] }]

[[body]]
name = "table"
on = "C"
solids = [{ cylinder = [300.0, 60.0], at = [0.0, 0.0, -60.0] }]

[[body]]
name = "head"
on = "head"
solids = [
    { cylinder = [70.0, 150.0], at = [0.0, 0.0, 0.0] },
    { cylinder = [110.0, 200.0], at = [0.0, -100.0, 150.0], axis = [0.0, 1.0, 0.0] },
]
"#
    };
}

/// Plausible bodies of `head-head-ca`, assumed: a fixed table 1000 × 800
/// with its face at Z 0, the fork on C (two arms beside the A pivot, 150
/// mm above the gauge point, and their bridge), the spindle Ø140 on A.
macro_rules! head_head_bodies {
    () => {
        r#"
[[body]]
name = "table"
on = "base"
solids = [{ box = [1000.0, 800.0, 60.0], at = [0.0, 0.0, -30.0] }]

[[body]]
name = "fork"
on = "C"
solids = [
    { box = [40.0, 160.0, 220.0], at = [-140.0, 0.0, 200.0] },
    { box = [40.0, 160.0, 220.0], at = [140.0, 0.0, 200.0] },
    { box = [320.0, 160.0, 60.0], at = [0.0, 0.0, 340.0] },
]

[[body]]
name = "spindle"
on = "head"
solids = [{ cylinder = [70.0, 200.0], at = [0.0, 0.0, 0.0] }]
"#
    };
}

/// Plausible bodies of `mill-3axis`, assumed: a fixed table 1000 × 500
/// with its face at Z 0 and a spindle housing Ø180.
macro_rules! mill_bodies {
    () => {
        r#"
[[body]]
name = "table"
on = "base"
solids = [{ box = [1000.0, 500.0, 60.0], at = [0.0, 0.0, -30.0] }]

[[body]]
name = "head"
on = "head"
solids = [{ cylinder = [90.0, 450.0], at = [0.0, 0.0, 0.0] }]
"#
    };
}

const TRUNNION_AC: &str = concat!(
    r#"
name = "A/C trunnion table (A tilts the table, C turns on it)"
type = "table"
control = "fanuc30i"
"#,
    linear_axes!(),
    r#"
[[rotary]]
name = "A"
on = "table"
axis = [-1, 0, 0]
center = [0, 0, -100]
min = -120.0
max = 30.0
max_velocity = 5400.0
rapid = 9000.0
max_acceleration = 1500.0
max_jerk = 30000.0

[[rotary]]
name = "C"
on = "table"
axis = [0, 0, -1]
center = [0, 0, 0]
rollover = true
max_velocity = 7200.0
rapid = 10800.0
max_acceleration = 2000.0
max_jerk = 40000.0
"#,
    standard_m_codes!(),
    r#"
10 = "clamp A"
11 = "unclamp A"
12 = "clamp C"
13 = "unclamp C"
"#,
    trunnion_bodies!("A", "x")
);

const TRUNNION_BC: &str = concat!(
    r#"
name = "B/C trunnion table (B tilts the table, C turns on it)"
type = "table"
control = "fanuc30i"
"#,
    linear_axes!(),
    r#"
[[rotary]]
name = "B"
on = "table"
axis = [0, -1, 0]
center = [0, 0, -100]
min = -120.0
max = 120.0
max_velocity = 5400.0
rapid = 9000.0
max_acceleration = 1500.0
max_jerk = 30000.0

[[rotary]]
name = "C"
on = "table"
axis = [0, 0, -1]
center = [0, 0, 0]
rollover = true
max_velocity = 7200.0
rapid = 10800.0
max_acceleration = 2000.0
max_jerk = 40000.0
"#,
    standard_m_codes!(),
    r#"
10 = "clamp B"
11 = "unclamp B"
12 = "clamp C"
13 = "unclamp C"
"#,
    trunnion_bodies!("B", "y")
);

const HEAD_TABLE_BC: &str = concat!(
    r#"
name = "Swivel head B with rotary table C"
type = "mixed"
control = "fanuc30i"
"#,
    linear_axes!(),
    r#"
[[rotary]]
name = "B"
on = "head"
axis = [0, 1, 0]
center = [0, 0, 150]
min = -110.0
max = 110.0
max_velocity = 7200.0
rapid = 10800.0
max_acceleration = 3000.0
max_jerk = 60000.0

[[rotary]]
name = "C"
on = "table"
axis = [0, 0, -1]
center = [0, 0, 0]
rollover = true
max_velocity = 7200.0
rapid = 10800.0
max_acceleration = 2000.0
max_jerk = 40000.0
"#,
    standard_m_codes!(),
    r#"
10 = "clamp B"
11 = "unclamp B"
12 = "clamp C"
13 = "unclamp C"
"#,
    head_table_bodies!()
);

const HEAD_HEAD_CA: &str = concat!(
    r#"
name = "Fork head C/A (C on the carriage carries A)"
type = "head"
control = "fanuc30i"
"#,
    linear_axes!(),
    r#"
[[rotary]]
name = "C"
on = "head"
axis = [0, 0, 1]
center = [0, 0, 150]
min = -360.0
max = 360.0
max_velocity = 10800.0
rapid = 14400.0
max_acceleration = 3600.0
max_jerk = 72000.0

[[rotary]]
name = "A"
on = "head"
axis = [1, 0, 0]
center = [0, 0, 150]
min = -110.0
max = 110.0
max_velocity = 7200.0
rapid = 10800.0
max_acceleration = 3000.0
max_jerk = 60000.0
"#,
    standard_m_codes!(),
    r#"
10 = "clamp C"
11 = "unclamp C"
12 = "clamp A"
13 = "unclamp A"
"#,
    head_head_bodies!()
);

const MILL_3AXIS: &str = concat!(
    r#"
name = "Three-axis vertical mill"
type = "none"
control = "fanuc30i"
"#,
    linear_axes!(),
    standard_m_codes!(),
    mill_bodies!()
);

/// Linear axes of a Haas machine as Haas lays them out: machine zero is the
/// home position and every axis travels negative from it (`G53 Z0.` is
/// the tool-change height). Rapid 1000 in/min (25.4 m/min) and cutting
/// feed 650 in/min (16.5 m/min) on X, Y and Z, from Haas's VF-2 and
/// UMC-750 specification sheets; acceleration and jerk are assumed
/// (as the other built-ins: 3 m/s², 50 m/s³).
macro_rules! haas_linear_axes {
    ($x:literal, $y:literal, $z:literal) => {
        concat!(
            "\n[[linear]]\nname = \"X\"\nmin = ",
            $x,
            "\nmax = 0.0\nmax_velocity = 16510.0\nrapid = 25400.0\nmax_acceleration = 3000.0\nmax_jerk = 50000.0\n",
            "\n[[linear]]\nname = \"Y\"\nmin = ",
            $y,
            "\nmax = 0.0\nmax_velocity = 16510.0\nrapid = 25400.0\nmax_acceleration = 3000.0\nmax_jerk = 50000.0\n",
            "\n[[linear]]\nname = \"Z\"\nmin = ",
            $z,
            "\nmax = 0.0\nmax_velocity = 16510.0\nrapid = 25400.0\nmax_acceleration = 3000.0\nmax_jerk = 50000.0\n"
        )
    };
}

/// Plausible bodies of `haas-umc750`, assumed: the platter Ø630 × 50 on
/// C with its face on the B axis (430 mm below the gauge line at home),
/// the trunnion's cradle on B (a plate under the platter, walls at its Y
/// ends), the base with the two trunnion supports, the spindle housing.
macro_rules! haas_umc750_bodies {
    () => {
        r#"
[[body]]
name = "bed"
on = "base"
solids = [
    { box = [1500.0, 1100.0, 100.0], at = [-381.0, -254.0, -1000.0] },
    { box = [400.0, 100.0, 450.0], at = [-381.0, -714.0, -725.0] },
    { box = [400.0, 100.0, 450.0], at = [-381.0, 206.0, -725.0] },
]

[[body]]
name = "cradle"
on = "B"
solids = [
    { box = [700.0, 780.0, 50.0], at = [-381.0, -254.0, -515.0] },
    { box = [700.0, 40.0, 150.0], at = [-381.0, -624.0, -465.0] },
    { box = [700.0, 40.0, 150.0], at = [-381.0, 116.0, -465.0] },
]

[[body]]
name = "table"
on = "C"
solids = [{ cylinder = [315.0, 50.0], at = [-381.0, -254.0, -480.0] }]

[[body]]
name = "head"
on = "head"
solids = [{ cylinder = [90.0, 450.0], at = [0.0, 0.0, 0.0] }]
"#
    };
}

/// Haas UMC-750: a B/C trunnion (B tilts the trunnion about Y, C turns the
/// platter on it). Travels X 30 in, Y 20 in, Z 20 in (762, 508, 508 mm);
/// B −35° … +120°, C endless (the stroke Autodesk's Haas NGC post gives
/// the UMC-750). Rotation senses as that post defines them for the table:
/// B about +Y, C about +Z (right-hand rule, the part carried by the axis).
/// The centres of rotation are the machine's MRZP settings (255–257),
/// measured per machine; here assumed: the C axis over the middle of the
/// X and Y travels, the B axis 430 mm below the gauge line at home, both
/// meeting on the platter's face. Rotary speeds are assumed (B 30 rev/min,
/// C 50 rev/min). The control is Haas with Setting 9 = INCH, Haas's
/// default in the US and what the corpus Haas program (no G20) needs.
/// M10–M13 are Haas's standard brake codes, not declared here.
const HAAS_UMC750: &str = concat!(
    r#"
name = "Haas UMC-750 (B/C trunnion)"
type = "table"
control = "haas"
"#,
    haas_linear_axes!("-762.0", "-508.0", "-508.0"),
    r#"
[[rotary]]
name = "B"
on = "table"
axis = [0, 1, 0]
center = [-381.0, -254.0, -430.0]
min = -35.0
max = 120.0
max_velocity = 7200.0
rapid = 10800.0
max_acceleration = 1500.0
max_jerk = 30000.0

[[rotary]]
name = "C"
on = "table"
axis = [0, 0, 1]
center = [-381.0, -254.0, 0.0]
rollover = true
max_velocity = 10800.0
rapid = 18000.0
max_acceleration = 2000.0
max_jerk = 40000.0

[parameters]
input_unit = "inch"
"#,
    haas_umc750_bodies!()
);

/// Plausible bodies of `haas-vf2-tr160`, assumed: the VF-2's table (its
/// face 610 mm below the gauge line at home) with the TR160's two
/// supports, its cradle on A, the platter Ø160 × 40 on B with its face on
/// the A axis, the spindle housing.
macro_rules! haas_vf2_tr160_bodies {
    () => {
        r#"
[[body]]
name = "bed"
on = "base"
solids = [
    { box = [1370.0, 356.0, 60.0], at = [-381.0, -203.0, -640.0] },
    { box = [80.0, 220.0, 200.0], at = [-611.0, -203.0, -510.0] },
    { box = [80.0, 220.0, 200.0], at = [-151.0, -203.0, -510.0] },
]

[[body]]
name = "cradle"
on = "A"
solids = [{ box = [300.0, 220.0, 40.0], at = [-381.0, -203.0, -510.0] }]

[[body]]
name = "table"
on = "B"
solids = [{ cylinder = [80.0, 40.0], at = [-381.0, -203.0, -480.0] }]

[[body]]
name = "head"
on = "head"
solids = [{ cylinder = [90.0, 450.0], at = [0.0, 0.0, 0.0] }]
"#
    };
}

/// Haas VF-2 with a TR160 trunnion: A tilts the trunnion about X (±120°),
/// the platter turns on it, endless. Haas names the TR160's platter B
/// (as the corpus program `haas_nx_vf2tr_5T.nc`, posted by NX for this
/// machine, does: `A0.0 B0.0`, B beyond 360). VF-2 travels X 30 in, Y
/// 16 in, Z 20 in (762, 406, 508 mm). Rotation senses ISO: +A turns the
/// table about −X, +B the platter about −Z at A 0. Assumed: the trunnion
/// over the middle of the X and Y travels, the A axis 440 mm below the
/// gauge line at home (the VF-2's table 24 in below the spindle nose, the
/// A axis 170 mm above the table), the platter's face on the A axis;
/// rotary speeds A 30 rev/min, B 50 rev/min. Setting 9 = INCH.
const HAAS_VF2_TR160: &str = concat!(
    r#"
name = "Haas VF-2 with TR160 trunnion (A tilts, B turns the platter)"
type = "table"
control = "haas"
"#,
    haas_linear_axes!("-762.0", "-406.0", "-508.0"),
    r#"
[[rotary]]
name = "A"
on = "table"
axis = [-1, 0, 0]
center = [-381.0, -203.0, -440.0]
min = -120.0
max = 120.0
max_velocity = 7200.0
rapid = 10800.0
max_acceleration = 1500.0
max_jerk = 30000.0

[[rotary]]
name = "B"
on = "table"
axis = [0, 0, -1]
center = [-381.0, -203.0, 0.0]
rollover = true
max_velocity = 10800.0
rapid = 18000.0
max_acceleration = 2000.0
max_jerk = 40000.0

[parameters]
input_unit = "inch"
"#,
    haas_vf2_tr160_bodies!()
);

/// The M functions of a SINUMERIK (840D sl / 828D programming manuals,
/// "M functions"): M0 stop, M1 optional stop, M2 and M30 program end,
/// M3 / M4 / M5 spindle, M6 tool change, M8 / M9 coolant. M17 (end of a
/// subprogram) is a word of the language, not a function of this table.
macro_rules! sinumerik_m_codes {
    () => {
        r#"
[m_codes]
0 = "stop"
1 = "optional_stop"
2 = "end"
3 = "spindle_cw"
4 = "spindle_ccw"
5 = "spindle_stop"
6 = "tool_change"
8 = "coolant_on"
9 = "coolant_off"
30 = "end"
"#
    };
}

/// Plausible bodies of `sinumerik-dmu-bc`, assumed: a bed under a round
/// table Ø600 × 60 on C, the spindle Ø140 from the gauge point to the
/// B pivot and the swivel housing Ø220 along the 45° B axis.
macro_rules! sinumerik_dmu_bodies {
    () => {
        r#"
[[body]]
name = "bed"
on = "base"
solids = [{ box = [1200.0, 1000.0, 100.0], at = [0.0, 0.0, -111.0] }]

[[body]]
name = "table"
on = "C"
solids = [{ cylinder = [300.0, 60.0], at = [0.0, 0.0, -60.0] }]

[[body]]
name = "head"
on = "head"
solids = [
    { cylinder = [70.0, 150.0], at = [0.0, 0.0, 0.0] },
    { cylinder = [110.0, 180.0], at = [0.0, -63.64, 86.36], axis = [0.0, 1.0, 1.0] },
]
"#
    };
}

/// A SINUMERIK machine of a common five-axis kind, after the DMU eVo and
/// DMU monoBLOCK machines: a swivel head B whose axis lies in the Y-Z
/// plane at 45° (B 0: spindle vertical; B 180: spindle horizontal, the
/// tool pointing towards −Y), carrying the spindle, and a rotary table C.
/// SINUMERIK kinematic type M: axis 1 (B) in the head, axis 2 (C) in the
/// table. The same machine as a swivel data record is
/// [`crate::SINUMERIK_BUILTIN_TC_CARR`]. Assumed, not a maker's figures:
/// the B axis crosses the spindle axis 150 mm above the gauge point, B
/// travels −5° … 180°, C is endless; linear axes, reference positions and
/// dynamics as the FANUC built-ins (`linear_axes`).
const SINUMERIK_DMU_BC: &str = concat!(
    r#"
name = "Swivel head B at 45 degrees with rotary table C (SINUMERIK, DMU style)"
type = "mixed"
control = "sinumerik"
"#,
    linear_axes!(),
    r#"
[[rotary]]
name = "B"
on = "head"
axis = [0, 1, 1]
center = [0, 0, 150]
min = -5.0
max = 180.0
max_velocity = 7200.0
rapid = 10800.0
max_acceleration = 3000.0
max_jerk = 60000.0

[[rotary]]
name = "C"
on = "table"
axis = [0, 0, -1]
center = [0, 0, 0]
rollover = true
max_velocity = 7200.0
rapid = 10800.0
max_acceleration = 2000.0
max_jerk = 40000.0

[parameters]
reference_1 = { Z = 500.0 }
reference_2 = { Z = 500.0 }
"#,
    sinumerik_m_codes!(),
    sinumerik_dmu_bodies!()
);

/// A HEIDENHAIN machine of the kind the corpus's hyperMILL programs are
/// written for (DMG DMU monoBLOCK type with a swivelling rotary table):
/// A tilts the table about X, C turns the platter on it. Laid out as a TNC
/// machine is: the machine datum at the top of the Z travel, so that
/// `L Z0 R0 FMAX M91` sends the spindle to its highest point, and the
/// linear axes of a DMU 85 class machine (X 850, Y 650, Z 650 mm of
/// travel; `L Y-425 M91` is the front end of the Y travel). Assumed, not
/// a maker's figures: the table face 500 mm below the spindle nose at the
/// top, the C axis at X 0 Y 0, the A axis 100 mm below the table face,
/// A −120° … +30°, C endless; dynamics as the other built-ins. Rotation
/// senses as the table axes of `trunnion-ac` (the part carried by the
/// axis turns about −X and −Z): PLANE SPATIAL SPA+90 SPC+180 with SEQ−
/// then stands at A −90, C 0, as the corpus programs' own comments say.
/// Plausible bodies, assumed: the table Ø600 × 40 on C with its face
/// 100 mm above the A axis, the cradle on A, the bed with the supports of
/// the A axis, the spindle housing.
const HEIDENHAIN_DMU_AC: &str = r#"
name = "Swivelling rotary table A/C (HEIDENHAIN TNC 640, DMU monoBLOCK style)"
type = "table"
control = "heidenhain"

[[linear]]
name = "X"
min = -425.0
max = 425.0
max_velocity = 20000.0
rapid = 30000.0
max_acceleration = 3000.0
max_jerk = 50000.0

[[linear]]
name = "Y"
min = -425.0
max = 225.0
max_velocity = 20000.0
rapid = 30000.0
max_acceleration = 3000.0
max_jerk = 50000.0

[[linear]]
name = "Z"
min = -650.0
max = 0.0
max_velocity = 20000.0
rapid = 30000.0
max_acceleration = 3000.0
max_jerk = 50000.0

[[rotary]]
name = "A"
on = "table"
axis = [-1, 0, 0]
center = [0, 0, -600]
min = -120.0
max = 30.0
max_velocity = 5400.0
rapid = 9000.0
max_acceleration = 1500.0
max_jerk = 30000.0

[[rotary]]
name = "C"
on = "table"
axis = [0, 0, -1]
center = [0, 0, -500]
rollover = true
max_velocity = 7200.0
rapid = 10800.0
max_acceleration = 2000.0
max_jerk = 40000.0

[parameters]
reference_1 = { Z = 0.0 }
reference_2 = { Z = 0.0 }

[m_codes]
0 = "stop"
1 = "optional_stop"
2 = "end"
3 = "spindle_cw"
4 = "spindle_ccw"
5 = "spindle_stop"
6 = "tool_change"
8 = "coolant_on"
9 = "coolant_off"
30 = "end"

[[body]]
name = "bed"
on = "base"
solids = [
    { box = [1200.0, 1000.0, 100.0], at = [0.0, 0.0, -1060.0] },
    { box = [100.0, 400.0, 450.0], at = [-460.0, 0.0, -785.0] },
    { box = [100.0, 400.0, 450.0], at = [460.0, 0.0, -785.0] },
]

[[body]]
name = "cradle"
on = "A"
solids = [
    { box = [780.0, 640.0, 40.0], at = [0.0, 0.0, -580.0] },
    { box = [40.0, 640.0, 100.0], at = [-370.0, 0.0, -550.0] },
    { box = [40.0, 640.0, 100.0], at = [370.0, 0.0, -550.0] },
]

[[body]]
name = "table"
on = "C"
solids = [{ cylinder = [300.0, 40.0], at = [0.0, 0.0, -540.0] }]

[[body]]
name = "head"
on = "head"
solids = [{ cylinder = [90.0, 450.0], at = [0.0, 0.0, 0.0] }]
"#;

/// The library: name and machine-file text.
const LIBRARY: [(&str, &str); 9] = [
    ("trunnion-ac", TRUNNION_AC),
    ("trunnion-bc", TRUNNION_BC),
    ("head-table-bc", HEAD_TABLE_BC),
    ("head-head-ca", HEAD_HEAD_CA),
    ("mill-3axis", MILL_3AXIS),
    ("haas-umc750", HAAS_UMC750),
    ("haas-vf2-tr160", HAAS_VF2_TR160),
    ("sinumerik-dmu-bc", SINUMERIK_DMU_BC),
    ("heidenhain-dmu-ac", HEIDENHAIN_DMU_AC),
];

/// Names of the built-in machines.
pub fn builtin_names() -> &'static [&'static str] {
    const NAMES: [&str; LIBRARY.len()] = {
        let mut names = [""; LIBRARY.len()];
        let mut i = 0;
        while i < LIBRARY.len() {
            names[i] = LIBRARY[i].0;
            i += 1;
        }
        names
    };
    &NAMES
}

/// The machine-file text of a built-in machine, by name.
pub fn builtin_source(name: &str) -> Option<&'static str> {
    LIBRARY
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
}

/// A built-in machine by name.
pub fn builtin(name: &str) -> Option<Machine> {
    builtin_source(name).and_then(|text| Machine::from_toml(text).ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_reads() {
        for name in builtin_names() {
            let text = builtin_source(name).expect("listed");
            if let Err(e) = Machine::from_toml(text) {
                panic!("{name}: {e}");
            }
        }
    }
}
