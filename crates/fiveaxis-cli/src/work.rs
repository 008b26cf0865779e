//! The work's solids on the command line: `--fixture`, `--stock` and
//! `--part` take an STL file (binary or ASCII) or `box:x0,y0,z0,x1,y1,z1`,
//! in the work frame; `--place X,Y,Z` puts the work zero in the table
//! frame (default: the offsets' G54).

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use fiveaxis_collide::work::WorkShape;
use fiveaxis_machine::Vec3;

use crate::InputError;

/// Triangles at most in one STL file (a 100,000-triangle fixture is a
/// detailed one).
const MAX_TRIANGLES: usize = 20_000_000;

/// A named solid of the work.
#[derive(Clone, Debug)]
pub struct NamedShape {
    /// The file's stem, or `box`.
    pub name: String,
    /// The solid, in the work frame.
    pub shape: WorkShape,
}

/// Reads `value` of option `option`: a `box:` or an STL file.
pub fn read(option: &str, value: &str) -> Result<NamedShape, InputError> {
    if let Some(numbers) = value.strip_prefix("box:") {
        let v = numbers_of(option, value, numbers, 6)?;
        let (a, b) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
        let (min, max) = (a.inf(&b), a.sup(&b));
        if (max - min).min() <= 0.0 {
            return Err(InputError(format!(
                "error: {option} {value}: the box has no volume (two corners share a coordinate)"
            )));
        }
        return Ok(NamedShape {
            name: "box".into(),
            shape: WorkShape::Box { min, max },
        });
    }
    let path = Path::new(value);
    let file = File::open(path).map_err(|e| InputError::io(value, &e))?;
    let mesh = stl_io::read_stl(&mut BufReader::new(file)).map_err(|e| {
        InputError(format!(
            "error: {option} {value}: not an STL file ({e}); give an STL file or box:x0,y0,z0,x1,y1,z1"
        ))
    })?;
    if mesh.faces.is_empty() {
        return Err(InputError(format!(
            "error: {option} {value}: the STL file has no triangles"
        )));
    }
    if mesh.faces.len() > MAX_TRIANGLES {
        return Err(InputError(format!(
            "error: {option} {value}: {} triangles, more than the {MAX_TRIANGLES} a work solid may have",
            mesh.faces.len()
        )));
    }
    let point = |i: usize| {
        let p = mesh.vertices[i].0;
        Vec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
    };
    let triangles: Vec<[Vec3; 3]> = mesh
        .faces
        .iter()
        .map(|f| {
            [
                point(f.vertices[0]),
                point(f.vertices[1]),
                point(f.vertices[2]),
            ]
        })
        .collect();
    if triangles
        .iter()
        .flatten()
        .any(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(InputError(format!(
            "error: {option} {value}: a vertex is not a finite number"
        )));
    }
    let name = path
        .file_stem()
        .map_or_else(|| value.to_string(), |s| s.to_string_lossy().into_owned());
    Ok(NamedShape {
        name,
        shape: WorkShape::Mesh(triangles),
    })
}

/// Reads `--place X,Y,Z`.
pub fn read_place(value: &str) -> Result<Vec3, InputError> {
    let v = numbers_of("--place", value, value, 3)?;
    Ok(Vec3::new(v[0], v[1], v[2]))
}

/// `count` comma-separated finite numbers.
fn numbers_of(option: &str, value: &str, text: &str, count: usize) -> Result<Vec<f64>, InputError> {
    let numbers: Vec<f64> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .filter(|v: &Vec<f64>| v.len() == count)
        .ok_or_else(|| {
            InputError(format!(
                "error: {option} {value}: expected {count} numbers separated by commas"
            ))
        })?;
    Ok(numbers)
}

/// Writes the surface of `dexels` to `path` as a binary STL file, whole
/// or not at all (a temporary file beside it, renamed).
pub fn write_stl(path: &Path, dexels: &fiveaxis_stock::dexel::Dexels) -> Result<(), InputError> {
    let shown = path.display().to_string();
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut triangles = Vec::new();
    dexels.triangles(|t| {
        let v = |p: &Vec3| stl_io::Vector::new([p.x as f32, p.y as f32, p.z as f32]);
        let n = (t[1] - t[0]).cross(&(t[2] - t[0])).normalize();
        triangles.push(stl_io::Triangle {
            normal: v(&n),
            vertices: [v(&t[0]), v(&t[1]), v(&t[2])],
        });
    });
    let mut builder = tempfile::Builder::new();
    builder.prefix(".fiveaxis-");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // A new file gets the mode the umask leaves, as any other.
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut file = builder
        .tempfile_in(dir)
        .map_err(|e| InputError::io(&shown, &e))?;
    if let Ok(m) = std::fs::metadata(path) {
        let _ = std::fs::set_permissions(file.path(), m.permissions());
    }
    {
        let mut w = std::io::BufWriter::new(file.as_file_mut());
        stl_io::write_stl(&mut w, triangles.iter()).map_err(|e| InputError::io(&shown, &e))?;
        std::io::Write::flush(&mut w).map_err(|e| InputError::io(&shown, &e))?;
    }
    file.persist(path)
        .map_err(|e| InputError::io(&shown, &e.error))?;
    Ok(())
}
