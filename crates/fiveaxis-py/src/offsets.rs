//! `fiveaxis._native.Offsets`: offset memory (tool, work, setup error)
//! from an offsets file, its text, or a Python dict of the same shape.

use std::path::PathBuf;

use fiveaxis_machine::Offsets;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use crate::errors::{dict_error, file_error, input_error};
use crate::inputs::read_data_file;

/// Offset memory.
#[pyclass(name = "Offsets", module = "fiveaxis._native", frozen)]
#[derive(Debug, Default)]
pub struct PyOffsets {
    pub offsets: Offsets,
}

/// Deepest nesting of a dict handed in (an offsets file has three levels).
const MAX_DEPTH: usize = 8;

/// A Python value as a TOML value: dicts (string or integer keys), lists
/// and tuples, booleans, integers, floats and strings.
fn to_toml(value: &Bound<'_, PyAny>, path: &str, depth: usize) -> Result<toml::Value, String> {
    if depth > MAX_DEPTH {
        return Err(format!("`{path}`: nested too deep for offsets"));
    }
    if value.is_instance_of::<PyBool>() {
        return value
            .extract::<bool>()
            .map(toml::Value::Boolean)
            .map_err(|e| e.to_string());
    }
    if let Ok(dict) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (key, item) in dict.iter() {
            let key = if key.is_instance_of::<PyString>() {
                key.extract::<String>().map_err(|e| e.to_string())?
            } else if key.is_instance_of::<PyInt>() {
                key.str().map_err(|e| e.to_string())?.to_string()
            } else {
                return Err(format!(
                    "`{path}`: keys must be strings or integers, not {}",
                    key.get_type().name().map_or("?".into(), |n| n.to_string())
                ));
            };
            let inner = if path.is_empty() {
                key.clone()
            } else {
                format!("{path}.{key}")
            };
            table.insert(key, to_toml(&item, &inner, depth + 1)?);
        }
        return Ok(toml::Value::Table(table));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items: Vec<Bound<'_, PyAny>> = value
            .try_iter()
            .map_err(|e| e.to_string())?
            .collect::<PyResult<_>>()
            .map_err(|e| e.to_string())?;
        return items
            .iter()
            .map(|item| to_toml(item, path, depth + 1))
            .collect::<Result<Vec<_>, _>>()
            .map(toml::Value::Array);
    }
    // A numpy array (or anything with `tolist` and `ndim`): its nested
    // lists.
    if value.hasattr("ndim").unwrap_or(false) && value.hasattr("tolist").unwrap_or(false) {
        let list = value.call_method0("tolist").map_err(|e| e.to_string())?;
        if !list.is(value) {
            return to_toml(&list, path, depth + 1);
        }
    }
    if value.is_instance_of::<PyString>() {
        return value
            .extract::<String>()
            .map(toml::Value::String)
            .map_err(|e| e.to_string());
    }
    if value.is_instance_of::<PyInt>() {
        return match value.extract::<i64>() {
            Ok(n) => Ok(toml::Value::Integer(n)),
            Err(_) => Err(format!("`{path}`: {value} is too large")),
        };
    }
    if value.is_instance_of::<PyFloat>() || value.hasattr("__float__").unwrap_or(false) {
        let x: f64 = value.extract().map_err(|e: PyErr| e.to_string())?;
        if !x.is_finite() {
            return Err(format!("`{path}`: {x} is not a finite number"));
        }
        return Ok(toml::Value::Float(x));
    }
    Err(format!(
        "`{path}`: a {} is not an offsets value",
        value
            .get_type()
            .name()
            .map_or("?".into(), |n| n.to_string())
    ))
}

#[pymethods]
impl PyOffsets {
    /// All offsets zero.
    #[new]
    fn new() -> Self {
        Self::default()
    }

    /// Offsets from the text of an offsets file; `file` names it in errors.
    #[staticmethod]
    #[pyo3(signature = (text, file = "<string>"))]
    fn from_toml(py: Python<'_>, text: &str, file: &str) -> PyResult<Self> {
        Offsets::from_toml(text)
            .map(|offsets| Self { offsets })
            .map_err(|e| file_error(py, file, &e))
    }

    /// Offsets from an offsets file.
    #[staticmethod]
    fn from_file(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let text = read_data_file(py, &path)?;
        Offsets::from_toml(&text)
            .map(|offsets| Self { offsets })
            .map_err(|e| file_error(py, &path.display().to_string(), &e))
    }

    /// Offsets from a dict shaped as an offsets file:
    /// `{"tools": {1: {"length": 100.0}}, "work": {"G54": [0, 0, 0]}}`.
    #[staticmethod]
    fn from_dict(py: Python<'_>, data: &Bound<'_, PyDict>) -> PyResult<Self> {
        let value = to_toml(data.as_any(), "", 0)
            .map_err(|m| input_error(py, m, Some("<dict>"), None, None, None))?;
        let text = toml::to_string(&value)
            .map_err(|e| input_error(py, e.to_string(), Some("<dict>"), None, None, None))?;
        Offsets::from_toml(&text)
            .map(|offsets| Self { offsets })
            .map_err(|e| dict_error(py, "<dict>", &e))
    }

    /// Tool offsets by number: length, length wear, radius, radius wear.
    #[getter]
    fn tools<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for (n, t) in &self.offsets.tools {
            let d = PyDict::new(py);
            d.set_item("length", t.length)?;
            d.set_item("length_wear", t.length_wear)?;
            d.set_item("radius", t.radius)?;
            d.set_item("radius_wear", t.radius_wear)?;
            out.set_item(n, d)?;
        }
        Ok(out)
    }

    /// Work offsets G54 … G59 and the external offset EXT.
    #[getter]
    fn work<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for (k, w) in self.offsets.work.iter().enumerate() {
            out.set_item(format!("G{}", 54 + k), (w.x, w.y, w.z))?;
        }
        let e = self.offsets.external;
        out.set_item("EXT", (e.x, e.y, e.z))?;
        Ok(out)
    }
}
