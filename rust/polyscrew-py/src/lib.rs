//! placeholder
use pyo3::prelude::*;
#[pymodule]
fn _polyscrew(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
