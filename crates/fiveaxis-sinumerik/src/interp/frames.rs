//! Frames as values: the frame functions and the chain operator `:`.
//!
//! A frame maps a point `p'` of its new system to the old one as
//! `p = T + R · S · M · p'`: translation (coarse plus fine), then the
//! rotation (RPY: about Z, the new Y, the newest X, the `FrameValue`
//! convention, K2), then scale and mirror per axis. The geometry axes are
//! those named `X`, `Y`, `Z`; other axes have translation, scale and
//! mirror only.
//!
//! `A : B` applies `A`, then `B` in `A`'s new system: translations
//! `T = T_A + R_A S_A M_A T_B`, rotations `R = R_A R_B` (back to RPY
//! angles through 3×3 matrices), scale factors multiplied and mirrors
//! combined per axis. Taking `S_A M_A` through `R_B` is exact when `A`
//! scales uniformly and mirrors nothing; otherwise the result keeps the
//! per-axis factors, an approximation (a non-uniform scale followed by a
//! rotation is no frame of this form).

use crate::{FrameAxis, FrameValue};

type M3 = [[f64; 3]; 3];

const GEOMETRY: [&str; 3] = ["X", "Y", "Z"];

fn neutral(axis: &str) -> FrameAxis {
    FrameAxis {
        axis: axis.to_string(),
        tr: 0.0,
        fi: 0.0,
        rt: 0.0,
        sc: 1.0,
        mi: false,
    }
}

fn is_neutral(a: &FrameAxis) -> bool {
    a.tr == 0.0 && a.fi == 0.0 && a.rt == 0.0 && a.sc == 1.0 && !a.mi
}

fn get(f: &FrameValue, axis: &str) -> FrameAxis {
    f.axes
        .iter()
        .find(|a| a.axis == axis)
        .cloned()
        .unwrap_or_else(|| neutral(axis))
}

fn mul(a: &M3, b: &M3) -> M3 {
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, cell) in row.iter_mut().enumerate() {
            *cell = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    r
}

fn apply(m: &M3, v: [f64; 3]) -> [f64; 3] {
    let mut r = [0.0; 3];
    for (i, cell) in r.iter_mut().enumerate() {
        *cell = (0..3).map(|k| m[i][k] * v[k]).sum();
    }
    r
}

fn rot(axis: usize, degrees: f64) -> M3 {
    let (s, c) = degrees.to_radians().sin_cos();
    match axis {
        0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
    }
}

/// The rotation of RPY angles (about X, Y, Z): `Rz · Ry · Rx`.
fn rpy(angles: [f64; 3]) -> M3 {
    mul(
        &mul(&rot(2, angles[2]), &rot(1, angles[1])),
        &rot(0, angles[0]),
    )
}

/// The RPY angles (about X, Y, Z, degrees) of a rotation matrix.
fn angles(m: &M3) -> [f64; 3] {
    let sy = (-m[2][0]).clamp(-1.0, 1.0);
    let b = sy.asin();
    if sy.abs() > 1.0 - 1e-12 {
        // Gimbal lock: the X and Z rotations share an axis; all on Z.
        let c = (-m[0][1]).atan2(m[1][1]);
        return [0.0, b.to_degrees(), c.to_degrees()].map(tidy);
    }
    let a = m[2][1].atan2(m[2][2]);
    let c = m[1][0].atan2(m[0][0]);
    [a.to_degrees(), b.to_degrees(), c.to_degrees()].map(tidy)
}

/// Rounding noise of the matrix arithmetic removed.
fn tidy(x: f64) -> f64 {
    if x.abs() < 1e-9 { 0.0 } else { x }
}

fn factor(a: &FrameAxis) -> f64 {
    if a.mi { -a.sc } else { a.sc }
}

/// The frame of `CTRANS`, `CFINE`, `CROT`, `CSCALE`, `CMIRROR` from
/// axis / value pairs (the value ignored for `CMIRROR`).
pub(crate) fn build(name: &str, items: &[(String, f64)]) -> Result<FrameValue, String> {
    let mut f = FrameValue::default();
    for (axis, value) in items {
        let axis = axis.to_ascii_uppercase();
        let pos = match f.axes.iter().position(|a| a.axis == axis) {
            Some(p) => p,
            None => {
                f.axes.push(neutral(&axis));
                f.axes.len() - 1
            }
        };
        let a = &mut f.axes[pos];
        match name {
            "CTRANS" => a.tr = *value,
            "CFINE" => a.fi = *value,
            "CROT" => {
                if !GEOMETRY.contains(&axis.as_str()) {
                    return Err(format!(
                        "CROT rotates about the geometry axes X, Y, Z, not {axis}"
                    ));
                }
                a.rt = *value;
            }
            "CSCALE" => a.sc = *value,
            _ => a.mi = true,
        }
    }
    f.axes.retain(|a| !is_neutral(a));
    Ok(f)
}

/// `a : b`.
pub(crate) fn chain(a: &FrameValue, b: &FrameValue) -> FrameValue {
    let ga: Vec<FrameAxis> = GEOMETRY.iter().map(|n| get(a, n)).collect();
    let gb: Vec<FrameAxis> = GEOMETRY.iter().map(|n| get(b, n)).collect();
    let ra = rpy([ga[0].rt, ga[1].rt, ga[2].rt]);
    let rb = rpy([gb[0].rt, gb[1].rt, gb[2].rt]);
    // R_A · S_A · M_A
    let mut la = ra;
    for row in &mut la {
        for (j, cell) in row.iter_mut().enumerate() {
            *cell *= factor(&ga[j]);
        }
    }
    let tb = apply(&la, [gb[0].tr, gb[1].tr, gb[2].tr]);
    let fb = apply(&la, [gb[0].fi, gb[1].fi, gb[2].fi]);
    let r = angles(&mul(&ra, &rb));

    let mut names: Vec<String> = GEOMETRY.iter().map(|s| s.to_string()).collect();
    for x in a.axes.iter().chain(&b.axes) {
        if !names.contains(&x.axis) {
            names.push(x.axis.clone());
        }
    }
    let mut out = FrameValue::default();
    for name in names {
        let (x, y) = (get(a, &name), get(b, &name));
        let c = match GEOMETRY.iter().position(|g| *g == name) {
            Some(i) => FrameAxis {
                axis: name,
                tr: tidy(x.tr + tb[i]),
                fi: tidy(x.fi + fb[i]),
                rt: r[i],
                sc: x.sc * y.sc,
                mi: x.mi != y.mi,
            },
            None => FrameAxis {
                axis: name,
                tr: x.tr + factor(&x) * y.tr,
                fi: x.fi + factor(&x) * y.fi,
                rt: 0.0,
                sc: x.sc * y.sc,
                mi: x.mi != y.mi,
            },
        };
        if !is_neutral(&c) {
            out.axes.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(name: &str, items: &[(&str, f64)]) -> FrameValue {
        let items: Vec<(String, f64)> = items.iter().map(|(a, v)| (a.to_string(), *v)).collect();
        build(name, &items).expect("frame")
    }

    #[test]
    fn translation_then_rotation_keeps_the_translation() {
        let f = chain(
            &frame("CTRANS", &[("X", 10.0)]),
            &frame("CROT", &[("Z", 90.0)]),
        );
        assert_eq!(get(&f, "X").tr, 10.0);
        assert!((get(&f, "Z").rt - 90.0).abs() < 1e-9);
    }

    #[test]
    fn rotation_then_translation_turns_the_translation() {
        let f = chain(
            &frame("CROT", &[("Z", 90.0)]),
            &frame("CTRANS", &[("X", 10.0)]),
        );
        assert!(get(&f, "X").tr.abs() < 1e-9);
        assert!((get(&f, "Y").tr - 10.0).abs() < 1e-9);
    }

    #[test]
    fn rotations_about_two_axes_compose_as_matrices() {
        let f = chain(
            &frame("CROT", &[("Z", 90.0)]),
            &frame("CROT", &[("X", 90.0)]),
        );
        let back = rpy([get(&f, "X").rt, get(&f, "Y").rt, get(&f, "Z").rt]);
        let want = mul(&rot(2, 90.0), &rot(0, 90.0));
        for i in 0..3 {
            for j in 0..3 {
                assert!((back[i][j] - want[i][j]).abs() < 1e-9);
            }
        }
    }
}
