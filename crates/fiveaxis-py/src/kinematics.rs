//! Vectorised kinematics: forward kinematics of machine positions, every
//! inverse solution of tips and directions, and the rotary choice the
//! control makes along a path. One call per array, no Python per point.

use fiveaxis_control::Controller;
use fiveaxis_machine::{Joints, MAX_AXES, Machine, Offsets, Vec3, principal, turn_angle};
use numpy::ndarray::{Array1, Array2, Array3, ArrayView1, ArrayView2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::errors::invalid;
use crate::machine::PyMachine;

/// Two numpy arrays.
type Pair<'py, A, B> = (Bound<'py, A>, Bound<'py, B>);

/// How far a solution's forward direction may be from the asked one
/// (unit vectors) before it is not a solution.
const DIRECTION_MATCH: f64 = 1e-9;

/// Checks an `(n, cols)` array: its width and that every entry is finite.
fn check_2d(py: Python<'_>, name: &str, a: &ArrayView2<'_, f64>, cols: usize) -> PyResult<()> {
    if a.ncols() != cols {
        return Err(invalid(
            py,
            format!("{name} must have shape (n, {cols}), not {:?}", a.shape()),
        ));
    }
    if let Some(((i, j), x)) = a.indexed_iter().find(|(_, x)| !x.is_finite()) {
        return Err(invalid(
            py,
            format!("{name}[{i}, {j}] is {x}, not a finite number"),
        ));
    }
    Ok(())
}

/// Checks a tool-length array: `n` entries, each finite.
fn check_lengths(py: Python<'_>, a: &ArrayView1<'_, f64>, n: usize) -> PyResult<()> {
    if a.len() != n {
        return Err(invalid(
            py,
            format!(
                "tool_length must be one number or have {n} entries, not {}",
                a.len()
            ),
        ));
    }
    if let Some((i, x)) = a.indexed_iter().find(|(_, x)| !x.is_finite()) {
        return Err(invalid(
            py,
            format!("tool_length[{i}] is {x}, not a finite number"),
        ));
    }
    Ok(())
}

/// Tips and directions `(n, 3)` and tool lengths for the same `n` poses:
/// `n`, or the error that says what does not fit.
fn check_poses(
    py: Python<'_>,
    tips: &ArrayView2<'_, f64>,
    dirs: &ArrayView2<'_, f64>,
    lengths: &ArrayView1<'_, f64>,
) -> PyResult<usize> {
    check_2d(py, "tips", tips, 3)?;
    check_2d(py, "directions", dirs, 3)?;
    let n = tips.nrows();
    if dirs.nrows() != n {
        return Err(invalid(
            py,
            format!(
                "tips has {n} rows and directions {}: they must match",
                dirs.nrows()
            ),
        ));
    }
    check_lengths(py, lengths, n)?;
    Ok(n)
}

fn row3(a: &ArrayView2<'_, f64>, i: usize) -> Vec3 {
    Vec3::new(a[[i, 0]], a[[i, 1]], a[[i, 2]])
}

/// A unit direction from row `i`, or an error for a zero vector.
fn unit_row(py: Python<'_>, dirs: &ArrayView2<'_, f64>, i: usize) -> PyResult<Vec3> {
    let d = row3(dirs, i);
    let n = d.norm();
    if n.is_nan() || n <= 1e-12 || !n.is_finite() {
        return Err(invalid(
            py,
            format!("directions[{i}] is not a direction (length {n})"),
        ));
    }
    Ok(d / n)
}

/// Forward kinematics: `(n, k)` machine positions and `n` tool lengths to
/// tips and unit tool directions `(n, 3)` in the table frame.
#[pyfunction]
pub fn forward<'py>(
    py: Python<'py>,
    machine: &Bound<'py, PyMachine>,
    joints: PyReadonlyArray2<'py, f64>,
    tool_length: PyReadonlyArray1<'py, f64>,
) -> PyResult<Pair<'py, PyArray2<f64>, PyArray2<f64>>> {
    let machine = &machine.get().machine;
    let joints = joints.as_array();
    let lengths = tool_length.as_array();
    let k = machine.axis_count();
    check_2d(py, "joints", &joints, k)?;
    let n = joints.nrows();
    check_lengths(py, &lengths, n)?;
    let mut tips = Vec::with_capacity(3 * n);
    let mut dirs = Vec::with_capacity(3 * n);
    let mut j: Joints = [0.0; MAX_AXES];
    for (i, row) in joints.rows().into_iter().enumerate() {
        for (slot, x) in j.iter_mut().zip(row.iter()) {
            *slot = *x;
        }
        let pose = machine.forward(&j, lengths[i]);
        tips.extend_from_slice(pose.tip.as_slice());
        dirs.extend_from_slice(pose.dir.as_slice());
    }
    let shape =
        |v: Vec<f64>| Array2::from_shape_vec((n, 3), v).map_err(|e| invalid(py, e.to_string()));
    Ok((shape(tips)?.into_pyarray(py), shape(dirs)?.into_pyarray(py)))
}

/// The rotary angle pairs (up to two; machine order) pointing the tool
/// along `dir`, each checked by forward kinematics. `held` is what a free
/// axis keeps at a singular direction. Machines with one rotary axis get
/// the one angle that reaches `dir`; without rotary axes, `dir` must be
/// the tool direction.
fn rotary_solutions(
    machine: &Machine,
    dir: &Vec3,
    held: [f64; 2],
) -> (Vec<[f64; 2]>, Option<usize>) {
    let first = machine.linear.len();
    let reaches = |pair: &[f64; 2]| {
        let mut j: Joints = [0.0; MAX_AXES];
        for (k, a) in pair.iter().enumerate().take(machine.rotary.len()) {
            j[first + k] = *a;
        }
        (machine.forward(&j, 0.0).dir - dir).norm() <= DIRECTION_MATCH.sqrt()
    };
    match machine.rotary.len() {
        2 => {
            let found = machine.orientations(dir, held);
            (found.pairs().to_vec(), found.free_axis)
        }
        1 => {
            let axis = &machine.rotary[0];
            let t0 = machine.tool_direction.into_inner();
            // A head axis turns the tool onto dir; a table axis turns the
            // part the other way.
            let angle = turn_angle(&axis.axis, &t0, dir).map(|a| match axis.on {
                fiveaxis_machine::Side::Head => principal(a),
                fiveaxis_machine::Side::Table => principal(-a),
            });
            match angle {
                Some(a) => {
                    let pair = [a, 0.0];
                    (if reaches(&pair) { vec![pair] } else { vec![] }, None)
                }
                // The tool lies on the rotation line: any angle (held).
                None => {
                    let pair = [held[0], 0.0];
                    (if reaches(&pair) { vec![pair] } else { vec![] }, Some(0))
                }
            }
        }
        _ => {
            let pair = [0.0, 0.0];
            (if reaches(&pair) { vec![pair] } else { vec![] }, None)
        }
    }
}

/// The machine position with rotary angles `pair` whose tool tip of
/// length `length` is at `tip` (table frame).
fn position(machine: &Machine, pair: &[f64; 2], tip: &Vec3, length: f64) -> Joints {
    let first = machine.linear.len();
    let mut j: Joints = [0.0; MAX_AXES];
    for (k, a) in pair.iter().enumerate().take(machine.rotary.len()) {
        j[first + k] = *a;
    }
    let gauge = machine.gauge_for_tip(&j, tip, length);
    j[..3].copy_from_slice(gauge.as_slice());
    j
}

/// Every inverse solution: for tips and directions `(n, 3)` (table frame)
/// and tool lengths, machine positions `(n, 2, k)` (unused solutions NaN),
/// how many solutions each point has `(n,)`, and which rotary axis was
/// free at a singular direction (`-1`: none).
#[pyfunction]
#[pyo3(signature = (machine, tips, directions, tool_length, held))]
#[allow(clippy::type_complexity)]
pub fn inverse<'py>(
    py: Python<'py>,
    machine: &Bound<'py, PyMachine>,
    tips: PyReadonlyArray2<'py, f64>,
    directions: PyReadonlyArray2<'py, f64>,
    tool_length: PyReadonlyArray1<'py, f64>,
    held: (f64, f64),
) -> PyResult<(
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray1<u8>>,
    Bound<'py, PyArray1<i8>>,
)> {
    let machine = &machine.get().machine;
    let (tips, dirs, lengths) = (
        tips.as_array(),
        directions.as_array(),
        tool_length.as_array(),
    );
    let n = check_poses(py, &tips, &dirs, &lengths)?;
    if !(held.0.is_finite() && held.1.is_finite()) {
        return Err(invalid(py, "held angles must be finite"));
    }
    let k = machine.axis_count();
    let mut out = Array3::from_elem((n, 2, k), f64::NAN);
    let mut count = Array1::zeros(n);
    let mut free = Array1::from_elem(n, -1i8);
    for i in 0..n {
        let dir = unit_row(py, &dirs, i)?;
        let tip = row3(&tips, i);
        let (pairs, free_axis) = rotary_solutions(machine, &dir, [held.0, held.1]);
        for (s, pair) in pairs.iter().enumerate().take(2) {
            let j = position(machine, pair, &tip, lengths[i]);
            for a in 0..k {
                out[[i, s, a]] = j[a];
            }
        }
        count[i] = pairs.len() as u8;
        if let Some(f) = free_axis.filter(|_| !pairs.is_empty()) {
            free[i] = f as i8;
        }
    }
    Ok((
        out.into_pyarray(py),
        count.into_pyarray(py),
        free.into_pyarray(py),
    ))
}

/// The control's choice along a path: for each point, the rotary angles
/// TCPC would command from where the previous point left the axes (the
/// first from `start`), and the linear axes that put the tip there. A
/// point no rotary position reaches gets NaN and `False` in the second
/// array, and the axes stay where they were.
#[pyfunction]
#[pyo3(signature = (machine, tips, directions, tool_length, start))]
pub fn inverse_choice<'py>(
    py: Python<'py>,
    machine: &Bound<'py, PyMachine>,
    tips: PyReadonlyArray2<'py, f64>,
    directions: PyReadonlyArray2<'py, f64>,
    tool_length: PyReadonlyArray1<'py, f64>,
    start: (f64, f64),
) -> PyResult<Pair<'py, PyArray2<f64>, PyArray1<bool>>> {
    let machine = &machine.get().machine;
    if machine.rotary.len() != 2 {
        return Err(invalid(
            py,
            format!(
                "the control's rotary choice needs two rotary axes; {} has {}",
                machine.name,
                machine.rotary.len()
            ),
        ));
    }
    let (tips, dirs, lengths) = (
        tips.as_array(),
        directions.as_array(),
        tool_length.as_array(),
    );
    let n = check_poses(py, &tips, &dirs, &lengths)?;
    if !(start.0.is_finite() && start.1.is_finite()) {
        return Err(invalid(py, "start angles must be finite"));
    }
    let controller = Controller::new(machine, Offsets::default());
    let k = machine.axis_count();
    let mut out = Array2::from_elem((n, k), f64::NAN);
    let mut reached = Array1::from_elem(n, false);
    let mut current = [start.0, start.1];
    for i in 0..n {
        let dir = unit_row(py, &dirs, i)?;
        if let Ok(pair) = controller.rotary_position_for(&dir, current) {
            let j = position(machine, &pair, &row3(&tips, i), lengths[i]);
            for a in 0..k {
                out[[i, a]] = j[a];
            }
            reached[i] = true;
            current = pair;
        }
    }
    Ok((out.into_pyarray(py), reached.into_pyarray(py)))
}
