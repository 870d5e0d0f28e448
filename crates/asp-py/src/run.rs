//! Running the planning pipeline from Python: without the GIL, interruptible by Ctrl-C.
//!
//! The pipeline runs on a worker thread while the calling thread waits for it with the GIL
//! released, so other Python threads keep running. Python handles a Ctrl-C by setting a flag that
//! only the interpreter looks at: every [`SIGNAL_INTERVAL`] the waiting thread takes the GIL back
//! and asks Python whether a signal is pending. When one is (`KeyboardInterrupt`, or whatever a
//! custom handler raised), it stops the search through the pipeline's [`StopToken`] (the same
//! token the CLI's Ctrl-C handler stops), waits for the worker to end, drops its result and raises
//! the signal's exception. The depth-first search and the optimisers alike look at the token.
//!
//! Limits: a single state whose tests take long (a path planner call, up to `rrt_time` seconds;
//! the first test of a part on a large mesh) delays the interrupt until it ends. Signals are only
//! seen on Python's main thread, as in Python itself.

use crate::errors::Error;
use asp_app::pipeline::{self, PlanResult, PlanSettings};
use asp_geom::Assembly;
use asp_search::StopToken;
use pyo3::prelude::*;
use std::panic;
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::Mutex;
use std::time::Duration;

/// How often, at most, the waiting thread asks Python for pending signals.
pub const SIGNAL_INTERVAL: Duration = Duration::from_millis(50);

/// The worker's stack: as the main thread's (deep models recurse in the loaders and the DFS).
const WORKER_STACK: usize = 8 << 20;

/// Plans `assembly` on a worker thread with the GIL released, stopping it early when a Python
/// signal handler raises.
pub fn plan(py: Python<'_>, assembly: Assembly, settings: &PlanSettings) -> PyResult<PlanResult> {
    let token = StopToken::new();
    let settings = PlanSettings { cancel: Some(token.clone()), ..settings.clone() };
    let result = interruptible(py, &token, move || pipeline::plan_assembly(assembly, &settings, None))?;
    result.map_err(|e| Error::from(e).into_py(py))
}

/// Runs `work` on a worker thread with the GIL released while this thread waits, asking Python
/// for pending signals every [`SIGNAL_INTERVAL`]; a raised signal stops `token` (which `work`
/// must watch), and once `work` has ended its result is dropped and the signal's exception is
/// raised. One thread per call: callers with many small jobs hand it a batch of them
/// (`asp._asp.plan_items`).
pub fn interruptible<T: Send>(py: Python<'_>, token: &StopToken, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    let (done, finished) = mpsc::channel::<()>();
    // a Receiver is Send but not Sync: the closures that wait without the GIL borrow it
    let finished = Mutex::new(finished);
    std::thread::scope(|scope| {
        let worker = std::thread::Builder::new()
            .name("asp-plan".into())
            .stack_size(WORKER_STACK)
            .spawn_scoped(scope, move || {
                // the channel closes when this closure ends, normally or by a panic
                let _done = done;
                work()
            })
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(format!("cannot start the planning thread: {e}")))?;
        let mut raised: Option<PyErr> = None;
        let wait = || py.detach(|| finished.lock().unwrap_or_else(|e| e.into_inner()).recv_timeout(SIGNAL_INTERVAL));
        while let Err(RecvTimeoutError::Timeout) = wait() {
            if raised.is_none() {
                if let Err(e) = py.check_signals() {
                    token.stop();
                    raised = Some(e);
                }
            }
        }
        let outcome = py.detach(|| worker.join());
        match (outcome, raised) {
            // a bug, not bad input: pyo3 turns the panic into a PanicException
            (Err(payload), _) => panic::resume_unwind(payload),
            (Ok(_), Some(e)) => Err(e),
            (Ok(result), None) => Ok(result),
        }
    })
}
