//! The work's solids on the command line: `--fixture`, `--stock` and
//! `--part` take an STL file (binary or ASCII) or `box:x0,y0,z0,x1,y1,z1`,
//! in the work frame; `--place X,Y,Z` puts the work zero in the table
//! frame (default: the offsets' G54).

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use fiveaxis_collide::work::WorkShape;
use fiveaxis_machine::Vec3;

use crate::InputError;

use fiveaxis_check::WorkChecks;
use fiveaxis_check::collision::{Collisions, WorkSolid};
use fiveaxis_check::stock::StockCheck;

/// Where the stock left at the end of a run is handed.
pub type KeptStock = std::sync::Arc<std::sync::Mutex<Option<fiveaxis_stock::Stock>>>;
use fiveaxis_machine::{Machine, Offsets};
use fiveaxis_stock::dexel::Dexels;

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
    let triangles = read_stl(&format!("{option} {value}"), path)?;
    let name = path
        .file_stem()
        .map_or_else(|| value.to_string(), |s| s.to_string_lossy().into_owned());
    Ok(NamedShape {
        name,
        shape: WorkShape::Mesh(triangles),
    })
}

/// The triangles of an STL file (binary or ASCII); `what` names it in
/// errors.
pub fn read_stl(what: &str, path: &Path) -> Result<Vec<[Vec3; 3]>, InputError> {
    let shown = path.display().to_string();
    let file = File::open(path).map_err(|e| InputError::io(&shown, &e))?;
    let mesh = stl_io::read_stl(&mut BufReader::new(file)).map_err(|e| {
        InputError(format!(
            "error: {what}: not an STL file ({e}); give an STL file or box:x0,y0,z0,x1,y1,z1"
        ))
    })?;
    if mesh.faces.is_empty() {
        return Err(InputError(format!(
            "error: {what}: the STL file has no triangles"
        )));
    }
    if mesh.faces.len() > MAX_TRIANGLES {
        return Err(InputError(format!(
            "error: {what}: {} triangles, more than the {MAX_TRIANGLES} a solid may have",
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
            "error: {what}: a vertex is not a finite number"
        )));
    }
    Ok(triangles)
}

/// Reads the STL files the machine file's `mesh` solids name, relative to
/// the machine file `file`.
pub fn read_body_meshes(machine: &mut Machine, file: &Path) -> Result<(), InputError> {
    let dir = file.parent().unwrap_or(Path::new("."));
    for mesh in &mut machine.meshes {
        let path = dir.join(&mesh.file);
        let what = format!("{}: mesh {}", file.display(), mesh.file);
        mesh.triangles = read_stl(&what, &path).map_err(|e| match std::fs::metadata(&path) {
            Err(io) => InputError(format!("error: {what}: {io}")),
            Ok(_) => e,
        })?;
    }
    Ok(())
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

/// The work's options, shared by `check` and `view`.
#[derive(Debug, Default, clap::Args)]
pub struct WorkArgs {
    /// Check collisions along every move: the machine's bodies, the tool,
    /// its shank and holder (the offsets file's tool shapes) and the
    /// fixtures. Implied by `--fixture`.
    #[arg(long)]
    pub collisions: bool,
    /// Parts nearer than this without touching are near misses, mm.
    #[arg(long, default_value_t = fiveaxis_check::collision::DEFAULT_CLEARANCE, value_parser = positive_mm)]
    pub clearance: f64,
    /// A fixture or clamp in the work frame: an STL file or
    /// `box:x0,y0,z0,x1,y1,z1` (repeatable).
    #[arg(long, value_name = "PATH.stl|box:…")]
    pub fixture: Vec<String>,
    /// Where the work zero stands in the table frame, `X,Y,Z` mm; default:
    /// the work offset G54.
    #[arg(long, value_name = "X,Y,Z")]
    pub place: Option<String>,
    /// The raw stock in the work frame, cut as the program runs: an STL
    /// file or `box:x0,y0,z0,x1,y1,z1`; with `--collisions`, `--fixture`,
    /// `--part` or `--stock-out` and no `--stock`: the stock the program
    /// declares (HEIDENHAIN `BLK FORM`), if any.
    #[arg(long, value_name = "PATH.stl|box:…")]
    pub stock: Option<String>,
    /// The stock model's cell size, mm.
    #[arg(long, default_value_t = fiveaxis_stock::DEFAULT_RESOLUTION, value_parser = positive_mm)]
    pub resolution: f64,
    /// The designed part in the work frame (STL or `box:`): cuts into it
    /// are gouges, material left on it is excess. Needs a stock.
    #[arg(long, value_name = "PATH.stl|box:…")]
    pub part: Option<String>,
    /// Gouges and excess count beyond this, mm.
    #[arg(long, default_value_t = DEFAULT_GOUGE_TOLERANCE, value_parser = positive_mm)]
    pub gouge_tolerance: f64,
    /// Write the stock left at the end as a binary STL file (one program).
    #[arg(long, value_name = "PATH.stl")]
    pub stock_out: Option<PathBuf>,
}

/// Gouges and excess count beyond this unless told (`--gouge-tolerance`),
/// mm.
const DEFAULT_GOUGE_TOLERANCE: f64 = 0.05;

/// Fills `dexels` with `shape` placed at the work zero `zero`.
fn fill(
    dexels: &mut Dexels,
    shape: &fiveaxis_collide::work::WorkShape,
    zero: &fiveaxis_machine::Vec3,
) {
    match shape {
        fiveaxis_collide::work::WorkShape::Box { min, max } => {
            dexels.fill_box(&(min + zero), &(max + zero));
        }
        fiveaxis_collide::work::WorkShape::Mesh(triangles) => {
            let moved: Vec<[fiveaxis_machine::Vec3; 3]> = triangles
                .iter()
                .map(|t| [t[0] + zero, t[1] + zero, t[2] + zero])
                .collect();
            dexels.fill_mesh(&moved);
        }
    }
}

/// A length in mm above zero.
fn positive_mm(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("`{text}` is not a length above 0 mm")),
    }
}

/// The work's solids and the collision check they ask for, read once for
/// all programs.
pub struct Work {
    collisions: bool,
    fixtures: Vec<NamedShape>,
    stock: Option<NamedShape>,
    part: Option<NamedShape>,
    stock_out: bool,
    zero: fiveaxis_machine::Vec3,
}

impl Work {
    /// Whether the work checks are asked for (collisions, a part, the
    /// stock written out): then the stock a program declares is cut.
    pub fn wants_work(&self) -> bool {
        self.collisions || self.part.is_some() || self.stock_out
    }

    pub fn read(args: &WorkArgs, programs: usize, offsets: &Offsets) -> Result<Self, InputError> {
        let mut fixtures = args
            .fixture
            .iter()
            .map(|f| read("--fixture", f))
            .collect::<Result<Vec<_>, _>>()?;
        // Fixtures of one name (two boxes) are told apart by their place
        // on the command line.
        let names: Vec<String> = fixtures.iter().map(|f| f.name.clone()).collect();
        for (k, fixture) in fixtures.iter_mut().enumerate() {
            if names.iter().filter(|n| **n == fixture.name).count() > 1 {
                fixture.name = format!("{} {}", fixture.name, k + 1);
            }
        }
        let zero = match &args.place {
            Some(place) => read_place(place)?,
            None => offsets.work[0],
        };
        if args.stock_out.is_some() && programs > 1 {
            return Err(InputError(
                "error: --stock-out writes the stock of one program: give one program".into(),
            ));
        }
        let stock = args
            .stock
            .as_deref()
            .map(|v| read("--stock", v))
            .transpose()?;
        let part = args
            .part
            .as_deref()
            .map(|v| read("--part", v))
            .transpose()?;
        Ok(Self {
            collisions: args.collisions || !fixtures.is_empty(),
            fixtures,
            stock,
            part,
            stock_out: args.stock_out.is_some(),
            zero,
        })
    }

    /// A fresh stock model for one program, if given.
    fn stock(
        &self,
        args: &WorkArgs,
        machine: &Machine,
        offsets: &Offsets,
    ) -> Result<Option<StockCheck>, InputError> {
        let Some(stock) = &self.stock else {
            return Ok(None);
        };
        self.stock_of(args, machine, offsets, &stock.shape)
            .map(Some)
    }

    /// A fresh stock model of `shape` for one program.
    fn stock_of(
        &self,
        args: &WorkArgs,
        machine: &Machine,
        offsets: &Offsets,
        shape: &fiveaxis_collide::work::WorkShape,
    ) -> Result<StockCheck, InputError> {
        let value = args.stock.as_deref().unwrap_or("BLK FORM");
        let (min, max) = shape.bounds();
        let (min, max) = (min + self.zero, max + self.zero);
        // One cell of margin: the mesh's walls fall inside the grid.
        let margin = fiveaxis_machine::Vec3::repeat(args.resolution);
        let mut dexels = Dexels::empty(&(min - margin), &(max + margin), args.resolution)
            .map_err(|e| InputError(format!("error: --stock {value}: {e}")))?;
        fill(&mut dexels, shape, &self.zero);
        let part = match &self.part {
            Some(part) => {
                let mut design = dexels.like();
                fill(&mut design, &part.shape, &self.zero);
                let shape = part.shape.placed(&self.zero).ok_or_else(|| {
                    InputError(format!(
                        "error: --part {}: the mesh cannot be used (no triangle with an area)",
                        args.part.as_deref().unwrap_or_default()
                    ))
                })?;
                Some(fiveaxis_stock::Part {
                    dexels: design,
                    depth: Box::new(move |p| fiveaxis_collide::work::depth_inside(&shape, p)),
                })
            }
            None => None,
        };
        let model = fiveaxis_stock::Stock::new(dexels, part, args.gouge_tolerance);
        Ok(StockCheck::new(machine, offsets, model, self.zero))
    }

    /// The work checks of one program: a fresh collision check and stock
    /// model as asked for, or, with the work asked for and no `--stock`,
    /// the stock the program declares (BLK FORM); and where the stock left
    /// at the end is handed.
    pub fn checks<'a>(
        &'a self,
        args: &'a WorkArgs,
        machine: &'a Machine,
        offsets: &'a Offsets,
    ) -> Result<(WorkChecks<'a>, KeptStock), InputError> {
        let collisions = self.collisions(args, machine, offsets)?;
        let mut stock = self.stock(args, machine, offsets)?;
        let kept: KeptStock = std::sync::Arc::new(std::sync::Mutex::new(None));
        if let Some(stock) = &mut stock {
            stock.keep_final(kept.clone());
        }
        let declared = (stock.is_none() && self.wants_work()).then(|| {
            let kept = kept.clone();
            Box::new(move |blk: &fiveaxis_control::Stock| {
                let shape = WorkShape::Box {
                    min: blk.min.into(),
                    max: blk.max.into(),
                };
                let mut check = self.stock_of(args, machine, offsets, &shape).ok()?;
                check.keep_final(kept);
                Some(check)
            }) as fiveaxis_check::DeclaredStock<'a>
        });
        Ok((
            WorkChecks {
                collisions,
                stock,
                declared,
            },
            kept,
        ))
    }

    /// A fresh collision check for one program, if asked for.
    fn collisions(
        &self,
        args: &WorkArgs,
        machine: &Machine,
        offsets: &Offsets,
    ) -> Result<Option<Collisions>, InputError> {
        if !self.collisions {
            return Ok(None);
        }
        let mut solids = Vec::new();
        for (fixture, value) in self.fixtures.iter().zip(&args.fixture) {
            let shape = fixture.shape.placed(&self.zero).ok_or_else(|| {
                InputError(format!(
                    "error: --fixture {value}: the mesh cannot be used (no triangle with an area)"
                ))
            })?;
            solids.push(WorkSolid {
                name: fixture.name.clone(),
                shape,
            });
        }
        Ok(Some(Collisions::new(
            machine,
            offsets,
            args.clearance,
            solids,
        )))
    }

    /// The fixtures for the page, placed in the table frame: their names
    /// and kinds (a box by its corners, a mesh by its triangles' range in
    /// the flat array of vertices that comes with them); a mesh beyond
    /// `max_triangles` in all is drawn as its bounding box.
    pub fn fixtures_for_page(&self, max_triangles: usize) -> (serde_json::Value, Vec<f32>) {
        let mut flat = Vec::new();
        let mut list = Vec::new();
        for f in &self.fixtures {
            let (lo, hi) = f.shape.bounds();
            let (lo, hi) = (lo + self.zero, hi + self.zero);
            let as_box = serde_json::json!({ "name": f.name, "min": [lo.x, lo.y, lo.z], "max": [hi.x, hi.y, hi.z] });
            match &f.shape {
                WorkShape::Mesh(triangles) if flat.len() / 9 + triangles.len() <= max_triangles => {
                    let first = flat.len() / 9;
                    for p in triangles.iter().flatten() {
                        let q = p + self.zero;
                        flat.extend([q.x as f32, q.y as f32, q.z as f32]);
                    }
                    list.push(serde_json::json!({ "name": f.name, "first": first, "count": triangles.len() }));
                }
                _ => list.push(as_box),
            }
        }
        (serde_json::Value::Array(list), flat)
    }
}
