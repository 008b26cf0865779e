//! Setup error data sets turned back to table position 0 (FANUC 30i
//! "Workpiece setting error compensation", A-79634E p.10 example, as in
//! functions-research.md §A.9).

use fiveaxis_machine::{SetupError, SetupErrorSet, Vec3, builtin};

fn close(a: &Vec3, b: &Vec3) -> bool {
    (a - b).norm() < 1e-12
}

#[test]
fn fanuc_common_set_example() {
    // Table C turning about -Z (the built-in A/C trunnion).
    let m = builtin("trunnion-ac").expect("built-in");
    let common = SetupErrorSet {
        origin: Vec3::new(0.0, 10.0, 0.0),
        table: vec![('C', -90.0)],
        ..Default::default()
    };
    let e0 = SetupError::from_set(&common, &m).expect("C is a table axis");
    // No.00: Δy = 10 measured at C−90° is Δx = 10 at C0.
    assert!(
        close(&e0.origin, &Vec3::new(10.0, 0.0, 0.0)),
        "{:?}",
        e0.origin
    );
    let first = SetupErrorSet {
        origin: Vec3::new(5.0, 0.0, 0.0),
        rotation: Vec3::new(0.0, 0.0, 2.0),
        table: vec![('C', 90.0)],
    };
    let e1 = SetupError::from_set(&first, &m).expect("C is a table axis");
    // No.01: Δx = 5, Δc = 2 at C90° is Δy = 5, Δc = 2 at C0.
    assert!(
        close(&e1.origin, &Vec3::new(0.0, 5.0, 0.0)),
        "{:?}",
        e1.origin
    );
    let (axis, angle) = e1.rotation.axis_angle().expect("a rotation");
    assert!((angle.to_degrees() - 2.0).abs() < 1e-12 && (axis.z - 1.0).abs() < 1e-12);
    // Combined: Δx = 10 and Δy = 5 (the common set's origin does not turn
    // with the selected set's rotation, which comes first), Δc = 2.
    let both = e0.after(&e1);
    assert!(
        close(&both.origin, &Vec3::new(10.0, 5.0, 0.0)),
        "{:?}",
        both.origin
    );
}

#[test]
fn rotation_order_is_x_then_y_then_z() {
    let m = builtin("mill-3axis").expect("built-in");
    let set = SetupErrorSet {
        rotation: Vec3::new(90.0, 90.0, 0.0),
        ..Default::default()
    };
    let e = SetupError::from_set(&set, &m).expect("no table axes named");
    // Rx(90) takes +Y to +Z, then Ry(90) takes +Z to +X.
    assert!(
        close(&e.vector(&Vec3::y()), &Vec3::x()),
        "{:?}",
        e.vector(&Vec3::y())
    );
    let p = Vec3::new(1.0, 2.0, 3.0);
    assert!(close(&e.inverse_point(&e.point(&p)), &p));
}

#[test]
fn unknown_table_axis_is_refused() {
    let m = builtin("trunnion-ac").expect("built-in");
    let set = SetupErrorSet {
        table: vec![('B', 10.0)],
        ..Default::default()
    };
    assert_eq!(SetupError::from_set(&set, &m), Err('B'));
}
