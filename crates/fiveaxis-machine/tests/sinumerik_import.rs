//! `import_tc_carr`: SINUMERIK swivel data records (`$TC_CARR`) as
//! machines, judged against the record's own kinematics written out here
//! by hand.
//!
//! The judge is the vector chain of the SINUMERIK documentation (W1 tool
//! offset, "Toolholder with orientation capability"; the commissioning
//! manual's swivel data chapter), not the importer's centres: for a head
//! (type T) the tip is the toolholder reference point P minus
//! l1 + R1·(l2 + R2·(l3 + L·z)); for a table (type P) a workpiece point q
//! stands in the machine at l2 + R1·(l3 + R2·(l4 + q)), so the tip on the
//! table is q = R2ᵀ·(R1ᵀ·(m − l2) − l3) − l4 for the machine point m; R1,
//! R2 turn by the right-hand rule about v1, v2. The closed forms below use
//! the plain rotation matrices about X, Y and Z, and for the 45° head
//! Rodrigues' formula worked out by hand.

use fiveaxis_machine::{
    Control, Joints, Machine, MachineType, SINUMERIK_BUILTIN, SINUMERIK_BUILTIN_TC_CARR, Side,
    TcCarrError, Vec3, builtin, import_tc_carr,
};
use nalgebra::{Matrix3, Rotation3, Unit};

const TOLERANCE: f64 = 1e-9;

/// Right-handed rotation matrices about X, Y, Z, degrees.
fn rx(deg: f64) -> Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

fn ry(deg: f64) -> Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

fn rz(deg: f64) -> Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

fn import(text: &str) -> Machine {
    import_tc_carr(text, None, None)
        .unwrap_or_else(|e| panic!("{e}"))
        .machine
}

fn error(text: &str) -> TcCarrError {
    match import_tc_carr(text, None, None) {
        Ok(_) => panic!("imported:\n{text}"),
        Err(e) => e,
    }
}

/// Joints X, Y, Z and two rotary positions.
fn joints(xyz: [f64; 3], r1: f64, r2: f64) -> Joints {
    let mut j = [0.0; 8];
    j[..3].copy_from_slice(&xyz);
    j[3] = r1;
    j[4] = r2;
    j
}

fn assert_close(got: Vec3, want: Vec3, what: &str) {
    assert!(
        (got - want).norm() <= TOLERANCE,
        "{what}: got {got:?}, want {want:?}"
    );
}

/// A small seeded generator (xorshift64*), values in [lo, hi).
struct Random(u64);

impl Random {
    fn next(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        lo + (hi - lo) * (bits as f64 / (1u64 << 53) as f64)
    }
}

// ----- the built-in SINUMERIK machine ---------------------------------------

#[test]
fn the_builtin_record_has_the_builtin_machines_kinematics() {
    let record = import_tc_carr(SINUMERIK_BUILTIN_TC_CARR, None, None).expect("imports");
    let m = &record.machine;
    let b = builtin(SINUMERIK_BUILTIN).expect("built in");
    assert_eq!(m.control, Control::Sinumerik);
    assert_eq!(m.name, "DMU_BC");
    assert_eq!(m.machine_type(), MachineType::Mixed);
    assert_eq!(m.linear, b.linear);
    assert_eq!(m.params, b.params);
    assert_eq!(m.m_codes, b.m_codes);
    assert_eq!(m.tool_direction, b.tool_direction);
    for (got, want) in m.rotary.iter().zip(&b.rotary) {
        assert_eq!(
            (got.name, got.on, got.limits, got.rollover, got.dynamics),
            (
                want.name,
                want.on,
                want.limits,
                want.rollover,
                want.dynamics
            )
        );
        assert_close(got.axis.into_inner(), want.axis.into_inner(), "axis");
    }
    assert_eq!(m.rotary.len(), 2);
    let mut random = Random(0x5EED_CA77);
    for _ in 0..500 {
        let j = joints(
            [
                random.next(-500.0, 500.0),
                random.next(-400.0, 400.0),
                random.next(-300.0, 500.0),
            ],
            random.next(-5.0, 180.0),
            random.next(-720.0, 720.0),
        );
        let length = random.next(0.0, 250.0);
        let (got, want) = (m.forward(&j, length), b.forward(&j, length));
        assert_close(got.tip, want.tip, "tip");
        assert_close(got.dir, want.dir, "direction");
    }
}

#[test]
fn the_builtin_record_against_the_45_degree_head_by_hand() {
    // B about u = (0, 1, 1)/√2 through 150 mm above the gauge point, C
    // the table about −Z through machine zero. Rodrigues for z about u:
    // R·z = z cos β + (u × z) sin β + u (u·z)(1 − cos β)
    //     = (sin β/√2, (1 − cos β)/2, (1 + cos β)/2).
    // Head: tip = XYZ − l1 − R·(l2 + L z) = XYZ + 150 z − (150 + L) R·z.
    // Table (l3 = l4 = 0): q = R_z(c)·m.
    let m = import(SINUMERIK_BUILTIN_TC_CARR);
    let xyz = [12.0, -30.0, 200.0];
    let length = 80.0;
    for (b, c) in [
        (0.0, 0.0),
        (90.0, 0.0),
        (180.0, 0.0),
        (180.0, 90.0),
        (45.0, -30.0),
    ] {
        let (s, co) = f64::to_radians(b).sin_cos();
        let rz_b = Vec3::new(s / 2f64.sqrt(), (1.0 - co) / 2.0, (1.0 + co) / 2.0);
        let machine_tip = Vec3::from(xyz) + Vec3::new(0.0, 0.0, 150.0) - (150.0 + length) * rz_b;
        let tip = rz(c) * machine_tip;
        let dir = rz(c) * rz_b;
        let pose = m.forward(&joints(xyz, b, c), length);
        assert_close(pose.tip, tip, &format!("tip at B{b} C{c}"));
        assert_close(pose.dir, dir, &format!("direction at B{b} C{c}"));
    }
    // B 180: the spindle lies horizontal, the tool towards −Y.
    let pose = m.forward(&joints([0.0; 3], 180.0, 0.0), 0.0);
    assert_close(pose.dir, Vec3::y(), "B180 direction");
}

#[test]
fn the_written_file_reads_back_and_explains_its_values() {
    let imported = import_tc_carr(SINUMERIK_BUILTIN_TC_CARR, None, None).expect("imports");
    let text = imported.to_toml();
    let back = Machine::from_toml(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(back, imported.machine);
    assert!(text.contains("control = \"sinumerik\""), "{text}");
    for needle in [
        "# Imported from SINUMERIK swivel data record 1 \"DMU_BC\"",
        "kinematic type M",
        "$TC_CARR7–9[1] (line 9)",
        "B: name from $TC_CARR35[1]",
        "C: $TC_CARR31/33 both 0: no limits",
        "C: rollover = true",
    ] {
        assert!(text.contains(needle), "no `{needle}` in\n{text}");
    }
}

// ----- type T: a B/A head ----------------------------------------------------

/// B (axis 1, about Y) on the carriage carries A (axis 2, about X), the A
/// pivot 100 mm above the gauge point, the B line 50 mm above A and 20 mm
/// towards +Y. Closed chain.
const HEAD_BA: &str = "\
; B/A fork head
N10 $TC_CARR23[1]='t'
N20 $TC_CARR15[1]=0 $TC_CARR16[1]=0 $TC_CARR17[1]=100   ; l3
N30 $TC_CARR4[1]=0 $TC_CARR5[1]=20 $TC_CARR6[1]=50      ; l2
N40 $TC_CARR1[1]=0 $TC_CARR2[1]=-20 $TC_CARR3[1]=-150   ; l1
N50 $TC_CARR7[1]=0 $TC_CARR8[1]=1 $TC_CARR9[1]=0        ; v1 B
N60 $TC_CARR10[1]=1 $TC_CARR11[1]=0 $TC_CARR12[1]=0     ; v2 A
N70 $TC_CARR21[1]=B $TC_CARR22[1]=A
N80 $TC_CARR30[1]=-100 $TC_CARR32[1]=100 $TC_CARR31[1]=-95 $TC_CARR33[1]=95
N90 $TC_CARR34[1]=\"HEAD_BA\"
";

#[test]
fn a_t_type_head_turns_the_tool_as_its_vector_chain_says() {
    let m = import(HEAD_BA);
    assert_eq!(m.machine_type(), MachineType::Head);
    let names: Vec<(char, Side)> = m.rotary.iter().map(|r| (r.name, r.on)).collect();
    assert_eq!(names, [('B', Side::Head), ('A', Side::Head)]);
    assert_eq!(m.rotary[0].limits, Some((-100.0, 100.0)));
    assert_eq!(m.rotary[1].limits, Some((-95.0, 95.0)));
    // tip = P − l1 − R_y(b)·l2 − R_y(b)·R_x(a)·(l3 + L z), P = X, Y, Z (the
    // chain closes). Worked out:
    //   R_y(b)·l2 = (50 sin b, 20, 50 cos b)
    //   R_y(b)·R_x(a)·(0, 0, h) = (h cos a sin b, −h sin a, h cos a cos b)
    let xyz = [100.0, -50.0, 20.0];
    let length = 60.0;
    for (b, a) in [
        (0.0, 0.0),
        (30.0, 0.0),
        (0.0, -45.0),
        (-60.0, 20.0),
        (90.0, 90.0),
    ] {
        let (sb, cb) = f64::to_radians(b).sin_cos();
        let (sa, ca) = f64::to_radians(a).sin_cos();
        let h = 100.0 + length;
        let tip = Vec3::from(xyz) + Vec3::new(0.0, 20.0, 150.0)
            - Vec3::new(50.0 * sb, 20.0, 50.0 * cb)
            - Vec3::new(h * ca * sb, -h * sa, h * ca * cb);
        let dir = Vec3::new(ca * sb, -sa, ca * cb);
        assert_close(ry(b) * rx(a) * Vec3::z(), dir, "the closed form");
        let pose = m.forward(&joints(xyz, b, a), length);
        assert_close(pose.tip, tip, &format!("tip at B{b} A{a}"));
        assert_close(pose.dir, dir, &format!("direction at B{b} A{a}"));
    }
}

#[test]
fn a_chain_that_does_not_close_shifts_the_linear_axes_only() {
    // The W1 example (08/2005, 2-92): l1 = (−200, 0, 0), l2 = 0, l3 =
    // (−100, 0, 0), v1 = X, v2 = (−1, 0, 1): the tool reference point sits
    // 300 mm in +X of the toolholder reference P.
    let text = "$TC_CARR1[1]=-200 $TC_CARR15[1]=-100\n\
                $TC_CARR7[1]=1 $TC_CARR10[1]=-1 $TC_CARR12[1]=1\n";
    let imported = import_tc_carr(text, None, None).expect("imports");
    let m = &imported.machine;
    assert!(
        imported
            .notes
            .iter()
            .any(|n| n.contains("X, Y, Z are the SINUMERIK's minus [-300, 0, 0]")),
        "{:?}",
        imported.notes
    );
    // tip = P − l1 − R1·l2 − R1·R2·(l3 + L z); the machine file's X, Y, Z
    // are P + (300, 0, 0).
    let u = Unit::new_normalize(Vec3::new(-1.0, 0.0, 1.0));
    let p = Vec3::new(10.0, 20.0, 30.0);
    let length = 75.0;
    for (a1, a2) in [(0.0, 0.0), (20.0, 0.0), (0.0, 40.0), (-35.0, 120.0)] {
        let r1 = rx(a1);
        let r2 = Rotation3::from_axis_angle(&u, f64::to_radians(a2)).into_inner();
        let l3 = Vec3::new(-100.0, 0.0, 0.0);
        let tip = p - Vec3::new(-200.0, 0.0, 0.0) - r1 * r2 * (l3 + length * Vec3::z());
        let dir = r1 * r2 * Vec3::z();
        let xyz = p + Vec3::new(300.0, 0.0, 0.0);
        let pose = m.forward(&joints(xyz.into(), a1, a2), length);
        assert_close(pose.tip, tip, &format!("tip at {a1}, {a2}"));
        assert_close(pose.dir, dir, &format!("direction at {a1}, {a2}"));
    }
}

// ----- type P: an A/C trunnion -----------------------------------------------

/// A tilts the table about −X (the vector reversed for a table axis), its
/// line through (10, 0, −100); C turns on it about −Z, its line through
/// (10, 5, 0). Closed chain.
const TRUNNION_AC: &str = "\
%_N_TRUNNION_SPF
$TC_CARR23[2]=\"p\" $TC_CARR34[2]=\"TRUNNION\"
$TC_CARR4[2]=10 $TC_CARR6[2]=-100              ; l2: machine zero -> A
$TC_CARR15[2]=0 $TC_CARR16[2]=5 $TC_CARR17[2]=100 ; l3: A -> C
$TC_CARR18[2]=-10 $TC_CARR19[2]=-5 $TC_CARR20[2]=0 ; l4 closes
$TC_CARR7[2]=-1 $TC_CARR12[2]=-1
$TC_CARR35[2]=\"A\" $TC_CARR36[2]=\"C\"
$TC_CARR30[2]=-120 $TC_CARR32[2]=30
";

#[test]
fn a_p_type_trunnion_turns_the_table_as_its_vector_chain_says() {
    let m = import(TRUNNION_AC);
    assert_eq!(m.machine_type(), MachineType::Table);
    assert_eq!(m.name, "TRUNNION");
    let names: Vec<(char, Side)> = m.rotary.iter().map(|r| (r.name, r.on)).collect();
    assert_eq!(names, [('A', Side::Table), ('C', Side::Table)]);
    assert_eq!(m.rotary[0].limits, Some((-120.0, 30.0)));
    assert_eq!(m.rotary[1].limits, None);
    // R1 = R_x(−a) (about −X), R2 = R_z(−c); their transposes R_x(a),
    // R_z(c). The machine point of the tip m = X, Y, Z − L z; on the
    // table q = R_z(c)·(R_x(a)·(m − l2) − l3) − l4, direction
    // R_z(c)·R_x(a)·z = (sin a sin c, −sin a cos c, cos a).
    let (l2, l3, l4) = (
        Vec3::new(10.0, 0.0, -100.0),
        Vec3::new(0.0, 5.0, 100.0),
        Vec3::new(-10.0, -5.0, 0.0),
    );
    let xyz = [40.0, 25.0, 150.0];
    let length = 90.0;
    for (a, c) in [
        (0.0, 0.0),
        (-90.0, 0.0),
        (0.0, 90.0),
        (-30.0, 45.0),
        (20.0, -200.0),
    ] {
        let machine_tip = Vec3::from(xyz) - length * Vec3::z();
        let tip = rz(c) * (rx(a) * (machine_tip - l2) - l3) - l4;
        let (sa, ca) = f64::to_radians(a).sin_cos();
        let (sc, cc) = f64::to_radians(c).sin_cos();
        let dir = Vec3::new(sa * sc, -sa * cc, ca);
        let pose = m.forward(&joints(xyz, a, c), length);
        assert_close(pose.tip, tip, &format!("tip at A{a} C{c}"));
        assert_close(pose.dir, dir, &format!("direction at A{a} C{c}"));
    }
}

// ----- type M: head B with an off-centre table C -----------------------------

/// B about +Y with its line 200 mm above the gauge point; C about −Z
/// through (100, 50, 0). Closed chains.
const MIXED_BC: &str = "\
$TC_CARR23[4]=M
$TC_CARR4[4]=0 $TC_CARR5[4]=0 $TC_CARR6[4]=200 $TC_CARR3[4]=-200
$TC_CARR15[4]=100 $TC_CARR16[4]=50 $TC_CARR18[4]=-100 $TC_CARR19[4]=-50
$TC_CARR8[4]=1 $TC_CARR12[4]=-1
";

#[test]
fn an_m_type_machine_turns_tool_and_table_as_its_vector_chains_say() {
    let imported = import_tc_carr(MIXED_BC, None, None).expect("imports");
    let m = &imported.machine;
    assert_eq!(m.machine_type(), MachineType::Mixed);
    // No names given: from the axis vectors.
    let names: Vec<(char, Side)> = m.rotary.iter().map(|r| (r.name, r.on)).collect();
    assert_eq!(names, [('B', Side::Head), ('C', Side::Table)]);
    assert_eq!(m.name, "SINUMERIK swivel data record 4");
    // Head: m = X, Y, Z − l1 − R_y(b)·(l2 + L z)
    //         = X, Y, Z + (0, 0, 200) − (200 + L)(sin b, 0, cos b).
    // Table: q = R_z(c)·(m − l3) − l4; direction R_z(c)·(sin b, 0, cos b).
    let (l3, l4) = (Vec3::new(100.0, 50.0, 0.0), Vec3::new(-100.0, -50.0, 0.0));
    let xyz = [-20.0, 35.0, 300.0];
    let length = 110.0;
    for (b, c) in [(0.0, 0.0), (90.0, 0.0), (-45.0, 90.0), (30.0, 135.0)] {
        let (sb, cb) = f64::to_radians(b).sin_cos();
        let head = Vec3::new(sb, 0.0, cb);
        let machine_tip = Vec3::from(xyz) + Vec3::new(0.0, 0.0, 200.0) - (200.0 + length) * head;
        let tip = rz(c) * (machine_tip - l3) - l4;
        let dir = rz(c) * head;
        let pose = m.forward(&joints(xyz, b, c), length);
        assert_close(pose.tip, tip, &format!("tip at B{b} C{c}"));
        assert_close(pose.dir, dir, &format!("direction at B{b} C{c}"));
    }
}

// ----- axis offsets and fine offsets ------------------------------------------

#[test]
fn axis_offsets_describe_the_machine_at_the_offset_positions() {
    // A single head axis A (about X) through 100 mm above the tool
    // adapter, with its initial state at A = 30: at A = θ the tool turns
    // by θ − 30. SINUMERIK: tip = P − l1 − R_x(θ − 30)·(l3 + L z). At A 0
    // the tool points along R_x(−30)·z = (0, sin 30, cos 30), and the
    // gauge point (the tool adapter) is 100 z − R_x(−30)·100 z from P:
    // the machine file's X, Y, Z are P + (0, −50, 100 − 100 cos 30).
    let text = "$TC_CARR17[1]=100 $TC_CARR3[1]=-100 $TC_CARR7[1]=1 $TC_CARR24[1]=30\n";
    let m = import(text);
    let half = f64::to_radians(30.0).cos();
    assert_close(
        m.tool_direction.into_inner(),
        Vec3::new(0.0, 0.5, half),
        "tool direction",
    );
    let p = Vec3::new(5.0, 6.0, 7.0);
    let xyz = p + Vec3::new(0.0, -50.0, 100.0 - 100.0 * half);
    let length = 40.0;
    for theta in [0.0, 30.0, 75.0, -60.0] {
        let r = rx(theta - 30.0);
        let tip = p + Vec3::new(0.0, 0.0, 100.0) - r * Vec3::new(0.0, 0.0, 100.0 + length);
        let pose = m.forward(&joints(xyz.into(), theta, 0.0), length);
        assert_close(pose.tip, tip, &format!("tip at A{theta}"));
        assert_close(pose.dir, r * Vec3::z(), &format!("direction at A{theta}"));
    }
}

#[test]
fn two_head_axes_with_offsets_follow_the_nested_chain() {
    // C/A head (C about Z on the carriage, A about X carried by C), offsets
    // 90 and −20. The SINUMERIK chain, nested: tip = P − l1 − R1(c − 90)·(l2
    // + R2(a + 20)·(l3 + L z)), R1 about Z, R2 about X, both as in the
    // initial state. The model's X, Y, Z differ from P by a constant: it is
    // taken at one pose and must hold at every other.
    let text = "$TC_CARR10[1]=1 $TC_CARR9[1]=1 $TC_CARR24[1]=90 $TC_CARR25[1]=-20\n\
                $TC_CARR15[1]=0 $TC_CARR16[1]=10 $TC_CARR17[1]=120\n\
                $TC_CARR4[1]=5 $TC_CARR5[1]=0 $TC_CARR6[1]=30\n\
                $TC_CARR1[1]=-5 $TC_CARR2[1]=-10 $TC_CARR3[1]=-150\n\
                $TC_CARR35[1]=\"C\" $TC_CARR36[1]=\"A\"\n";
    let m = import(text);
    let (l1, l2, l3) = (
        Vec3::new(-5.0, -10.0, -150.0),
        Vec3::new(5.0, 0.0, 30.0),
        Vec3::new(0.0, 10.0, 120.0),
    );
    let siemens = |p: Vec3, c: f64, a: f64, length: f64| {
        let (r1, r2) = (rz(c - 90.0), rx(a + 20.0));
        (
            p - l1 - r1 * (l2 + r2 * (l3 + length * Vec3::z())),
            r1 * r2 * Vec3::z(),
        )
    };
    let p0 = Vec3::new(1.0, 2.0, 3.0);
    let at_zero = m.forward(&joints(p0.into(), 0.0, 0.0), 0.0).tip;
    let shift = at_zero - siemens(p0, 0.0, 0.0, 0.0).0;
    let mut random = Random(0xC0FF_EE00);
    for _ in 0..200 {
        let p = Vec3::new(
            random.next(-300.0, 300.0),
            random.next(-300.0, 300.0),
            random.next(-300.0, 300.0),
        );
        let (c, a, length) = (
            random.next(-360.0, 360.0),
            random.next(-110.0, 110.0),
            random.next(0.0, 200.0),
        );
        let (tip, dir) = siemens(p, c, a, length);
        let pose = m.forward(&joints(p.into(), c, a), length);
        assert_close(pose.tip - shift, tip, "tip");
        assert_close(pose.dir, dir, "direction");
    }
}

#[test]
fn fine_offsets_add_to_their_base_fields() {
    let base = "$TC_CARR23[1]=\"M\" $TC_CARR8[1]=1 $TC_CARR12[1]=-1\n";
    let fine = format!(
        "{base}$TC_CARR6[1]=199 $TC_CARR46[1]=1 $TC_CARR3[1]=-200\n\
         $TC_CARR15[1]=100 $TC_CARR55[1]=0.5 $TC_CARR18[1]=-100 $TC_CARR58[1]=-0.5\n\
         $TC_CARR24[1]=10 $TC_CARR64[1]=-10\n"
    );
    let summed = format!(
        "{base}$TC_CARR6[1]=200 $TC_CARR3[1]=-200\n\
         $TC_CARR15[1]=100.5 $TC_CARR18[1]=-100.5\n"
    );
    let with_fine = import_tc_carr(&fine, None, None).expect("imports");
    assert_eq!(with_fine.machine, import(&summed));
    assert!(
        with_fine
            .notes
            .iter()
            .any(|n| n.contains("$TC_CARR4–6[1] plus fine offsets $TC_CARR46")),
        "{:?}",
        with_fine.notes
    );
    // 47–54 and 61–63 are no fields.
    let e = error("$TC_CARR47[1]=1");
    assert_eq!((e.line, e.column), (1, 9));
    assert!(e.message.contains("not a field"), "{e}");
}

// ----- records, base machine, errors ------------------------------------------

#[test]
fn a_record_is_picked_by_name_or_number_and_the_others_are_noted() {
    let text = format!("{TRUNNION_AC}{HEAD_BA}");
    let first = import_tc_carr(&text, None, None).expect("imports");
    assert_eq!(first.machine.name, "HEAD_BA");
    assert!(
        first
            .notes
            .iter()
            .any(|n| n.contains("not imported") && n.contains("2 \"TRUNNION\"")),
        "{:?}",
        first.notes
    );
    let by_name = import_tc_carr(&text, None, Some("trunnion")).expect("imports");
    assert_eq!(by_name.machine.name, "TRUNNION");
    let by_number = import_tc_carr(&text, None, Some("2")).expect("imports");
    assert_eq!(by_number.machine, by_name.machine);
    let e = import_tc_carr(&text, None, Some("SPINDLE")).expect_err("refused");
    assert_eq!(e.line, 0);
    assert!(
        e.message.contains("`SPINDLE`") && e.message.contains("1 \"HEAD_BA\""),
        "{e}"
    );
}

#[test]
fn the_base_machine_gives_the_linear_axes_and_m_codes() {
    use fiveaxis_machine::MFunction;
    let base = builtin("trunnion-ac").expect("built in");
    let m = import_tc_carr(HEAD_BA, Some(&base), None)
        .expect("imports")
        .machine;
    assert_eq!(m.linear, base.linear);
    assert_eq!(m.control, Control::Sinumerik);
    // trunnion-ac clamps A on M10/M11 and C on M12/M13: the head has A.
    assert_eq!(m.m_codes.get(10), Some(MFunction::Clamp('A')));
    assert_eq!(m.m_codes.get(12), None);
    assert_eq!(m.rotary[1].dynamics, base.rotary[0].dynamics);
}

#[test]
fn a_kinematic_type_other_than_t_p_m_is_alarm_14153() {
    for (value, column) in [("\"X\"", 15), ("'Q'", 15), ("0", 15), ("TP", 15)] {
        let text = format!("$TC_CARR8[1]=1\n$TC_CARR23[1]={value}\n");
        let e = error(&text);
        assert_eq!((e.line, e.column), (2, column), "{value}: {e}");
        assert!(e.message.contains("14153"), "{e}");
        assert!(e.to_string().starts_with("line 2, column 15: "), "{e}");
    }
}

#[test]
fn syntax_errors_give_line_and_column() {
    let cases = [
        (
            "$TC_CARR1[1]=1\n$TC_CARR2[1]=",
            (2, 14),
            "a value must follow",
        ),
        ("$TC_CARR1[1] 5", (1, 14), "`=` expected"),
        ("$TC_CARR1(1)=5", (1, 10), "[<record>]"),
        ("$TC_CARR1[x]=5", (1, 11), "whole number"),
        ("$TC_CARR1[1=5", (1, 12), "`]` expected"),
        ("N10 G0 X10", (1, 5), "`G0`"),
        ("$TC_CARR34[1]=\"open", (1, 15), "not closed"),
        ("$TC_CARR34[1]=HEAD", (1, 15), "\"string\""),
        ("$TC_CARR7[1]=1 $TC_CARR8[1]=1x", (1, 30), "cannot go on"),
        ("$TC_CARR7[1]=1 $TC_CARR21[1]=5", (1, 30), "axis name"),
        ("$TC_CARR66[1]=1", (1, 9), "not a field"),
        ("$TC_CARR3[0]=1", (1, 11), "start at 1"),
        ("; only\n\n  $TC_CARR1[1]=1 * 2", (3, 18), "unexpected `*`"),
    ];
    for (text, at, words) in cases {
        let e = error(text);
        assert_eq!((e.line, e.column), at, "{text:?}: {e}");
        assert!(e.message.contains(words), "{text:?}: {e}");
    }
}

#[test]
fn records_that_make_no_machine_are_refused_at_their_fields() {
    // Limits the wrong way round: at the maximum.
    let e = error("$TC_CARR7[1]=1\n$TC_CARR30[1]=10 $TC_CARR32[1]=-10\n");
    assert_eq!((e.line, e.column), (2, 32), "{e}");
    assert!(e.message.contains("above the minimum"), "{e}");
    // Axis 2 without axis 1.
    let e = error("$TC_CARR12[1]=1\n");
    assert_eq!((e.line, e.column), (1, 15), "{e}");
    assert!(e.message.contains("must be axis 1"), "{e}");
    // Two parallel axes: the machine file refuses them.
    let e = error("$TC_CARR23[1]=T $TC_CARR9[1]=1 $TC_CARR12[1]=-1\n");
    assert_eq!((e.line, e.column), (1, 15), "{e}");
    assert!(e.message.contains("parallel"), "{e}");
    // Nothing but a clear.
    let e = error("$TC_CARR1[1]=5\n$TC_CARR1[0]=0\n");
    assert_eq!(e.line, 0);
    assert!(e.message.contains("no swivel data record"), "{e}");
}

#[test]
fn a_record_without_axes_is_a_three_axis_machine_and_one_axis_a_four_axis_one() {
    let m = import("$TC_CARR34[1]=\"FIXED\"\n");
    assert_eq!(m.machine_type(), MachineType::None);
    assert!(m.rotary.is_empty());
    let m = import("$TC_CARR23[1]=P $TC_CARR9[1]=-1\n");
    assert_eq!(m.machine_type(), MachineType::Table);
    assert_eq!(m.rotary.len(), 1);
    assert_eq!(m.rotary[0].name, 'C');
    // C of the base machine (sinumerik-dmu-bc) is endless.
    assert!(m.rotary[0].rollover);
}

#[test]
fn table_axis_offsets_only_turn_the_table_frame() {
    // A C table about −Z through (50, 20, 0), its initial state at C = 45.
    // SINUMERIK: q = R_z(c − 45)·(m − l2) − l3 (l3 closes the chain): the
    // table frame at C 45 is the reference. The model's table frame is the
    // one at C 0, so at C = c the tip on the table is R_z(c)·(m − l2) + l2,
    // the record's q turned by R_z(45) about the axis.
    let text = "$TC_CARR23[1]=P\r\n$TC_CARR9[1]=-1 $TC_CARR4[1]=50 $TC_CARR5[1]=20\r\n\
                $TC_CARR15[1]=-50 $TC_CARR16[1]=-20 $TC_CARR24[1]=45\r\n";
    let imported = import_tc_carr(text, None, None).expect("imports");
    assert!(
        imported
            .notes
            .iter()
            .any(|n| n.contains("the axis offsets turn the table")),
        "{:?}",
        imported.notes
    );
    let m = &imported.machine;
    assert_eq!(m.tool_direction.into_inner(), Vec3::z());
    let l2 = Vec3::new(50.0, 20.0, 0.0);
    let xyz = [10.0, -40.0, 60.0];
    let length = 30.0;
    for c in [0.0, 45.0, 90.0, -120.0] {
        let machine_tip = Vec3::from(xyz) - length * Vec3::z();
        let record_q = rz(c - 45.0) * (machine_tip - l2) + l2;
        let tip = rz(45.0) * (record_q - l2) + l2;
        let pose = m.forward(&joints(xyz, c, 0.0), length);
        assert_close(pose.tip, tip, &format!("tip at C{c}"));
        assert_close(pose.dir, Vec3::z(), &format!("direction at C{c}"));
    }
}
