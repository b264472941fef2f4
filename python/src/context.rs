//! One EGL context per thread, shared by every Renderer opened on that thread.
//!
//! The library's `Gpu` makes its context current when it is created and its drop releases
//! whatever is current, so two contexts on one thread would steal each other's binding. Renderers
//! opened on the same thread with the same device therefore share one `Gpu`; it is destroyed when
//! the last of them closes. A process forked after the context was made inherits a copy of the
//! driver's state that must not be touched: the child forgets (leaks) the inherited context and
//! opens its own.

use crate::errors::{self, Kind};
use pyo3::PyResult;
use std::cell::RefCell;
use std::sync::atomic::{AtomicU32, Ordering};
use viewsynth::gpu::{DeviceChoice, Gpu};

struct Shared {
    pid: u32,
    device: DeviceChoice,
    gpu: Gpu,
    users: usize,
}

/// The slot of one thread. At thread exit (and process exit, after the driver may already have
/// torn itself down) an open context is leaked rather than destroyed: only `release` frees it.
struct Slot(Option<Shared>);

impl Drop for Slot {
    fn drop(&mut self) {
        std::mem::forget(self.0.take());
    }
}

/// The process that first opened an EGL context. A child forked after that inherits the driver's
/// state (display, screen, its worker threads gone): Mesa then hangs on the first draw, even after
/// every context was closed, so a forked child refuses to open one at all.
static EGL_PROCESS: AtomicU32 = AtomicU32::new(0);

thread_local! {
    static OPEN: RefCell<Slot> = const { RefCell::new(Slot(None)) };
}

/// The library's parse of "auto", "surfaceless" or an EGL device index (as the CLI's --device).
pub fn parse_device(device: &str) -> PyResult<DeviceChoice> {
    device.parse().map_err(|e| errors::invalid("device", e))
}

/// This thread's context for `device`, opened on first use; each call counts one user.
pub fn acquire(device: DeviceChoice) -> PyResult<Gpu> {
    let opener = EGL_PROCESS.load(Ordering::SeqCst);
    if opener != 0 && opener != std::process::id() {
        return Err(errors::raise(
            Kind::Forked,
            format!(
                "this process ({}) was forked from process {opener} after that one had opened an EGL \
                 context; the GPU driver's state does not survive fork (rendering would hang). Start \
                 workers with multiprocessing's \"spawn\" or \"forkserver\" method (torch: \
                 DataLoader(multiprocessing_context=\"spawn\")), or open no Renderer (nor viewsynth.info()) \
                 in the parent before forking",
                std::process::id()
            ),
            None,
        ));
    }
    OPEN.with(|open| {
        let open = &mut open.borrow_mut().0;
        let pid = std::process::id();
        if let Some(shared) = open.as_ref() {
            if shared.pid != pid {
                // Inherited through fork: the parent's driver state, never to be used or freed here.
                std::mem::forget(open.take());
            }
        }
        match open.as_mut() {
            Some(shared) if shared.device == device => {
                shared.users += 1;
                Ok(shared.gpu.clone())
            }
            Some(shared) => Err(errors::raise(
                Kind::InvalidInput,
                format!(
                    "invalid device: this thread already has a Renderer open on {:?}; one EGL context per \
                     thread: close it first, or use another thread",
                    shared.device
                ),
                Some("device"),
            )),
            None => {
                let gpu = Gpu::new(device).map_err(errors::from_library)?;
                let _ = EGL_PROCESS.compare_exchange(0, pid, Ordering::SeqCst, Ordering::SeqCst);
                *open = Some(Shared {
                    pid,
                    device,
                    gpu: gpu.clone(),
                    users: 1,
                });
                Ok(gpu)
            }
        }
    })
}

/// One user of this thread's context is done; the last one destroys it. `gpu` is the handle
/// that user held (dropped here, before the context, so nothing outlives it).
pub fn release(gpu: Gpu) {
    drop(gpu);
    // try_with: during thread teardown the slot may already be gone (its destructor frees it).
    let _ = OPEN.try_with(|open| {
        let open = &mut open.borrow_mut().0;
        let last = match open.as_mut() {
            Some(shared) if shared.pid == std::process::id() => {
                shared.users = shared.users.saturating_sub(1);
                shared.users == 0
            }
            _ => false,
        };
        if last {
            *open = None;
        }
    });
}
