//! Between Python and Weft: overrides as TOML text, live values, 3-vectors, numpy arrays of
//! points and triangles, and Weft's refusals as Python exceptions.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::{PyIndexError, PyKeyError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use weft_scene::Override;
use weft_sim::{SimError, Value};
use weft_solver::glam::DVec3;

/// Weft's refusal as the Python exception a caller expects: a missing cloth or key is a
/// `KeyError`, a missing particle an `IndexError`, anything else a `ValueError`.
pub fn sim_error(e: SimError) -> PyErr {
    let m = e.to_string();
    match e {
        SimError::NoSuchCloth { .. } | SimError::UnknownKey { .. } => PyKeyError::new_err(m),
        SimError::NoSuchParticle { .. } => PyIndexError::new_err(m),
        _ => PyValueError::new_err(m),
    }
}

/// A TOML string literal (basic string, escaped).
fn toml_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", u32::from(c))),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// A Python value as TOML: bool, int, float, str, a list or tuple of them, or a dict (an
/// inline table).
pub fn toml_value(v: &Bound<'_, PyAny>) -> PyResult<String> {
    if v.is_instance_of::<PyBool>() {
        return Ok(if v.extract::<bool>()? {
            "true"
        } else {
            "false"
        }
        .into());
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(v.str()?.to_string());
    }
    if v.is_instance_of::<PyFloat>() {
        let x: f64 = v.extract()?;
        return Ok(if x.is_nan() {
            "nan".into()
        } else if x.is_infinite() {
            if x > 0.0 { "inf" } else { "-inf" }.into()
        } else {
            // Rust's shortest round-trip form, with a point so TOML reads a float.
            let s = format!("{x:?}");
            if s.contains(['.', 'e', 'E']) {
                s
            } else {
                format!("{s}.0")
            }
        });
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(toml_string(&s.to_cow()?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items: PyResult<Vec<String>> = v.try_iter()?.map(|i| toml_value(&i?)).collect();
        return Ok(format!("[{}]", items?.join(", ")));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut items = Vec::new();
        for (k, x) in d.iter() {
            let k: String = k
                .extract()
                .map_err(|_| PyTypeError::new_err("an inline table's keys must be strings"))?;
            items.push(format!("{} = {}", toml_string(&k), toml_value(&x)?));
        }
        return Ok(format!("{{ {} }}", items.join(", ")));
    }
    Err(PyTypeError::new_err(format!(
        "an override's value must be a bool, int, float, str, list, tuple or dict, got {}",
        v.get_type().name()?
    )))
}

/// `method` (as `sim.method`, first, as the CLI's `--method`) and `overrides` (dotted key →
/// value, in order) as the scene loader's overrides.
pub fn overrides(
    method: Option<&str>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<Override>> {
    let mut v: Vec<Override> = method
        .map(|m| Override {
            key: "sim.method".into(),
            value: toml_string(m),
        })
        .into_iter()
        .collect();
    if let Some(d) = overrides {
        for (k, x) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                PyTypeError::new_err("override keys must be strings such as \"sim.substeps\"")
            })?;
            v.push(Override {
                value: toml_value(&x)?,
                key,
            });
        }
    }
    Ok(v)
}

/// Three finite-or-not floats from a sequence of three numbers (a list, a tuple, an array).
pub fn vec3(v: &Bound<'_, PyAny>, what: &str) -> PyResult<DVec3> {
    let bad = || {
        PyTypeError::new_err(format!(
            "{what}: expected three numbers (x, y, z), got {}",
            v.repr().map_or_else(|_| "?".into(), |r| r.to_string())
        ))
    };
    if v.is_instance_of::<PyString>() {
        return Err(bad());
    }
    let items: Vec<f64> = v.extract().map_err(|_| bad())?;
    match items[..] {
        [x, y, z] => Ok(DVec3::new(x, y, z)),
        _ => Err(bad()),
    }
}

/// A live setting's value: a number (not a bool), a string, or three numbers.
pub fn value(v: &Bound<'_, PyAny>, key: &str) -> PyResult<Value> {
    if v.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(format!(
            "{key}: expected a number, a string or three numbers, got a bool"
        )));
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(Value::Text(s.to_cow()?.into_owned()));
    }
    if let Ok(x) = v.extract::<f64>() {
        return Ok(Value::Number(x));
    }
    vec3(v, key).map(|p| Value::Vector(p.to_array()))
}

/// Points as a new `(n, 3)` float64 array.
pub fn points_array<'py>(py: Python<'py>, points: &[DVec3]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = points.iter().flat_map(|p| p.to_array()).collect();
    match Array2::from_shape_vec((points.len(), 3), flat) {
        Ok(a) => a.into_pyarray(py),
        // A length that is three times the rows: cannot fail.
        Err(_) => PyArray2::zeros(py, (0, 3), false),
    }
}

/// Triangles as a new `(m, 3)` uint32 array.
pub fn triangles_array<'py>(py: Python<'py>, triangles: &[[u32; 3]]) -> Bound<'py, PyArray2<u32>> {
    let flat: Vec<u32> = triangles.iter().flatten().copied().collect();
    match Array2::from_shape_vec((triangles.len(), 3), flat) {
        Ok(a) => a.into_pyarray(py),
        Err(_) => PyArray2::zeros(py, (0, 3), false),
    }
}

/// `n` points from a float64 numpy array of shape `(n, 3)` (any strides); another type,
/// dtype or shape is refused, naming what was expected.
pub fn points_from(v: &Bound<'_, PyAny>, n: usize, what: &str) -> PyResult<Vec<DVec3>> {
    let expected = format!("a float64 numpy array of shape ({n}, 3)");
    let Ok(untyped) = v.cast::<PyUntypedArray>() else {
        return Err(PyTypeError::new_err(format!(
            "{what}: expected {expected}, got {} (numpy.asarray(x, dtype=numpy.float64) makes one)",
            v.get_type().name()?
        )));
    };
    let Ok(array) = v.cast::<PyArray2<f64>>() else {
        return Err(if untyped.ndim() != 2 {
            PyValueError::new_err(format!(
                "{what}: expected {expected}, got shape {:?}",
                untyped.shape()
            ))
        } else {
            PyTypeError::new_err(format!(
                "{what}: expected {expected}, got dtype {}",
                untyped.dtype().str()?
            ))
        });
    };
    let shape = untyped.shape();
    if shape != [n, 3] {
        return Err(PyValueError::new_err(format!(
            "{what}: expected {expected}, got shape {shape:?}"
        )));
    }
    let ro = array
        .try_readonly()
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?;
    let a = ro.as_array();
    Ok(a.rows()
        .into_iter()
        .map(|r| DVec3::new(r[0], r[1], r[2]))
        .collect())
}
