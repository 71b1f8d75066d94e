//! Python bindings of `polyscrew`: conversion and nothing else. This file is the registry:
//! the modules and what each adds to the Python module `polyscrew._polyscrew`.
//!
//! Every function has one shape: read the arguments (the two-step [`args::Arg`] reader: its
//! cost known before anything is converted) -> check the memory budget -> release the GIL
//! (`py.detach`) -> call the core -> map the error once ([`errors::to_py_err`]) -> wrap the
//! result as numpy arrays. The `.pyi` stub is generated from the doc comments of these files
//! (`scripts/generate_stub.py`): a function's doc opens with its Python signature.

mod angular_velocity;
mod args;
mod arrays;
mod denoise;
mod errors;
mod fcurve;
mod feature;
mod intent;
mod motion;
mod reduce;
mod sweep;

use pyo3::prelude::*;

/// The extension module `polyscrew._polyscrew`; `polyscrew/__init__.py` re-exports it.
#[pymodule]
fn _polyscrew(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    motion::register(m)?;
    angular_velocity::register(m)?;
    sweep::register(m)?;
    feature::register(m)?;
    fcurve::register(m)?;
    intent::register(m)?;
    denoise::register(m)?;
    reduce::register(m)?;
    Ok(())
}
