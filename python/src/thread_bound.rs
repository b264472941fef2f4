//! `ThreadBound`: what a Renderer holds, usable only on the thread that created it.

use crate::errors::{self, Kind};
use pyo3::PyResult;

/// A value usable only on the thread that made it: every access checks the thread and fails
/// with a catchable `WrongThreadError` elsewhere (pyo3's `unsendable` would raise a
/// `PanicException`, which `except Exception` does not catch). Dropped on another thread, the
/// value is leaked, never freed there.
pub struct ThreadBound<T> {
    owner: std::thread::ThreadId,
    pub value: std::mem::ManuallyDrop<T>,
}

// SAFETY: the value is reached only through `get`/`take`, which refuse every thread but the
// owner, and `Drop` frees it only on the owner: it never crosses threads.
unsafe impl<T> Send for ThreadBound<T> {}
// SAFETY: as above; a shared reference gives no access to the value off the owner thread.
unsafe impl<T> Sync for ThreadBound<T> {}

impl<T> ThreadBound<T> {
    pub fn new(value: T) -> Self {
        ThreadBound {
            owner: std::thread::current().id(),
            value: std::mem::ManuallyDrop::new(value),
        }
    }

    pub fn on_owner(&self) -> bool {
        std::thread::current().id() == self.owner
    }

    fn check(&self) -> PyResult<()> {
        if self.on_owner() {
            return Ok(());
        }
        Err(errors::raise(
            Kind::WrongThread,
            "this Renderer belongs to the thread that created it (its EGL context is current there \
             only); create one Renderer per thread, e.g. in threading.local()",
            None,
        ))
    }

    pub fn get(&self) -> PyResult<&T> {
        self.check()?;
        Ok(&self.value)
    }
}

impl<T> Drop for ThreadBound<T> {
    fn drop(&mut self) {
        if self.on_owner() {
            // SAFETY: dropped once, here, on the owner thread.
            unsafe { std::mem::ManuallyDrop::drop(&mut self.value) }
        }
    }
}
