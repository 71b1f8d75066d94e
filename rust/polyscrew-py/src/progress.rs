//! Long calls watched from the calling thread: the work runs on its own thread, GIL released,
//! while the caller's thread reports its progress to a Python callable and stops it on what
//! that callable raises or on a signal (Ctrl-C).

use std::sync::mpsc;
use std::time::Duration;

use polyscrew::{Error, Progress};
use pyo3::prelude::*;

use crate::args::type_name;
use crate::errors::{to_py_err, wrong_type};

/// How often the callable hears of the progress.
const INTERVAL: Duration = Duration::from_millis(100);

/// Runs `work` with a [`Progress`]. Without `callback` (or None), on this thread, GIL
/// released; a `callback` that is not callable is a `TypeError` before any work. With
/// one, on a thread of its own while this thread, every [`INTERVAL`] until the work ends,
/// takes the GIL, checks for signals and calls `callback(fraction)`: what either raises asks
/// the work to stop, and is raised once it has (the work's own result, finished or not, is
/// dropped); signals are checked once more when the work has ended.
pub fn watched<T: Send>(
    py: Python<'_>,
    function: &str,
    callback: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce(&Progress) -> PyResult<T> + Send,
) -> PyResult<T> {
    let progress = Progress::new();
    let Some(callback) = callback.filter(|c| !c.is_none()) else {
        return py.detach(|| work(&progress));
    };
    if !callback.is_callable() {
        return Err(wrong_type(format!(
            "{function}: progress: expected a callable or None, got {}",
            type_name(callback)
        )));
    }
    let callback: Py<PyAny> = callback.clone().unbind();
    let (result, raised) = py.detach(|| {
        std::thread::scope(|scope| {
            let (done, ended) = mpsc::channel::<()>();
            let progress = &progress;
            let worker = scope.spawn(move || {
                let out = work(progress);
                let _ = done.send(());
                out
            });
            let mut raised: Option<PyErr> = None;
            while let Err(mpsc::RecvTimeoutError::Timeout) = ended.recv_timeout(INTERVAL) {
                if raised.is_some() {
                    continue;
                }
                raised = Python::attach(|py| {
                    py.check_signals()
                        .and_then(|()| callback.call1(py, (progress.fraction(),)).map(drop))
                        .err()
                });
                if raised.is_some() {
                    progress.cancel();
                }
            }
            // A signal since the last look (the work ended in between) is raised too.
            let raised = raised.or_else(|| Python::attach(|py| py.check_signals().err()));
            (worker.join(), raised)
        })
    });
    if let Some(err) = raised {
        return Err(err);
    }
    result.unwrap_or_else(|_| Err(to_py_err(function, Error::Worker { what: "the work" })))
}
