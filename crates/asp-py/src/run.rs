//! Running the planning pipeline from Python: without the GIL, interruptible by Ctrl-C.
//!
//! The search runs on the calling thread with the GIL released, so other Python threads keep
//! running. Python handles a Ctrl-C by setting a flag that only the interpreter looks at; the
//! depth-first search calls its progress hook once per expanded state, and there, at most every
//! [`SIGNAL_INTERVAL`], the hook takes the GIL back and asks Python whether a signal is pending.
//! When one is (`KeyboardInterrupt`, or whatever a custom handler raised), the hook unwinds out of
//! the search with a private payload (`resume_unwind`: no panic message, no panic hook), the
//! search's owned state (world, checker, caches) is dropped, and the signal's exception is
//! raised in Python.
//!
//! Limits: the optimiser (`objective=`) takes no progress hook, so it cannot be interrupted
//! (bound it with `time_limit=`); a single state whose tests take long (a path planner call, up
//! to `rrt_time` seconds; the first test of a part on a large mesh) delays the interrupt until
//! the next state. Signals are only seen on Python's main thread, as in Python itself.

use crate::errors::Error;
use asp_geom::Assembly;
use asp_search::pipeline::{self, PlanResult, PlanSettings};
use asp_search::Progress;
use pyo3::prelude::*;
use std::panic::{self, AssertUnwindSafe};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How often, at most, the search asks Python for pending signals.
pub const SIGNAL_INTERVAL: Duration = Duration::from_millis(50);

/// The unwinding payload of an interrupted search.
struct Interrupted;

/// Plans `assembly` with the GIL released, stopping early when a Python signal handler raises.
pub fn plan(py: Python<'_>, assembly: Assembly, settings: &PlanSettings) -> PyResult<PlanResult> {
    let raised: Mutex<Option<PyErr>> = Mutex::new(None);
    let last_check = Mutex::new(Instant::now());
    let hook = |_: &Progress| {
        {
            let mut last = last_check.lock().unwrap_or_else(|e| e.into_inner());
            if last.elapsed() < SIGNAL_INTERVAL {
                return;
            }
            *last = Instant::now();
        }
        if let Err(e) = Python::attach(|py| py.check_signals()) {
            *raised.lock().unwrap_or_else(|e| e.into_inner()) = Some(e);
            panic::resume_unwind(Box::new(Interrupted));
        }
    };
    let outcome =
        py.detach(|| panic::catch_unwind(AssertUnwindSafe(|| pipeline::plan_assembly(assembly, settings, Some(&hook)))));
    match outcome {
        Ok(result) => result.map_err(|e| Error::from(e).into_py(py)),
        Err(payload) if payload.is::<Interrupted>() => {
            let e = raised.into_inner().unwrap_or_else(|e| e.into_inner());
            Err(e.unwrap_or_else(|| pyo3::exceptions::PyKeyboardInterrupt::new_err("planning interrupted")))
        }
        // a bug, not bad input: pyo3 turns the panic into a PanicException
        Err(payload) => panic::resume_unwind(payload),
    }
}
