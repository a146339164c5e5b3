//! The engine's cancellation token as a Python object: Python keeps it, hands it to long calls
//! and cancels it on Ctrl-C from the thread that waits for them.

use super::error::shield;
use crate::cancel::Cancel;
use pyo3::prelude::*;

/// A flag that stops the long engine calls it was given within one integration step.
#[pyclass(frozen, module = "thermojitter._core")]
pub struct CancelToken {
    pub(crate) inner: Cancel,
}

#[pymethods]
impl CancelToken {
    #[new]
    fn new() -> Self {
        CancelToken {
            inner: Cancel::new(),
        }
    }

    /// Asks every call running with this token to stop (they raise KeyboardInterrupt).
    fn cancel(&self) {
        self.inner.cancel();
    }

    #[getter]
    fn cancelled(&self) -> bool {
        self.inner.is_cancelled()
    }
}

/// Runs `f` under [`shield`] with the engine token of an optional Python token (a fresh one when
/// None): how every call that Ctrl-C can stop begins.
pub(crate) fn cancellable<T>(
    cancel: Option<&Bound<'_, CancelToken>>,
    f: impl FnOnce(&Cancel) -> PyResult<T>,
) -> PyResult<T> {
    let cancel = cancel.map_or_else(Cancel::new, |c| c.get().inner.clone());
    shield(|| f(&cancel))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<CancelToken>()?;
    Ok(())
}
