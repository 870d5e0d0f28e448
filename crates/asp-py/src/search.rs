//! `asp._asp.Search`: the stepped optimiser run of `asp.Assembly.search`
//! ([`asp_app::stepped::SteppedSearch`]): episodes on demand, each returning its transitions
//! as the lines of `transitions.jsonl`, Q models swapped in between episodes, and the plan at the
//! end. Every wait releases the GIL and looks at Python's signals every [`SIGNAL_INTERVAL`] as
//! `Assembly.plan` does: a Ctrl-C stops the running episode, ends the search and raises.

use crate::errors::Error;
use crate::run::SIGNAL_INTERVAL;
use crate::settings;
use asp_app::catalogue::{PolicySource, QPolicy, DEFAULT_EPSILON};
use asp_app::collect_q;
use asp_app::stepped::{Poll, SteppedSearch};
use asp_search::QUse;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

/// What one episode did (`asp.Episode` is built from it).
#[pyclass(frozen, get_all, module = "asp._asp", name = "EpisodeReport")]
pub struct EpisodeReport {
    /// Its transitions as lines of `transitions.jsonl` (empty without recording).
    pub transitions_jsonl: String,
    /// Episodes finished so far.
    pub episodes: u64,
    /// Its iterations.
    pub iterations: u64,
    /// Seconds since the previous episode ended.
    pub seconds: f64,
    /// The front's hypervolume (several objectives) or the best total so far.
    pub value: f64,
    /// Points on the front so far.
    pub front_size: usize,
    /// The search has ended after it.
    pub finished: bool,
    /// Every sequence has been explored.
    pub exhausted: bool,
    /// The time limit stopped it.
    pub stopped: bool,
    /// It reached the recording limit.
    pub capped: bool,
}

/// A stepped search (see the module documentation).
#[pyclass(frozen, module = "asp._asp", name = "Search")]
pub struct PySearch {
    inner: Mutex<Option<SteppedSearch>>,
    index: String,
    /// Swaps counted when the result was taken.
    swaps: AtomicUsize,
}

impl PySearch {
    /// Builds the maps and the problem of `assembly` for `Assembly.plan`'s keywords (without the
    /// GIL) and waits for the first episode.
    pub fn start(py: Python<'_>, assembly: Arc<asp_geom::Assembly>, dict: &Bound<'_, PyDict>, record: bool) -> PyResult<Self> {
        let mut plan = settings::plan_settings(dict).map_err(|e| e.into_py(py))?;
        if plan.optimise.is_none() {
            return Err(Error::config("objective: a search needs objectives").into_py(py));
        }
        // the index tells the learner how to load the model as it was loaded
        plan.unit = Some(assembly.units.clone());
        plan.up = Some(assembly.up);
        plan.fixed = assembly.parts.iter().filter(|p| p.fixed).map(|p| p.name.clone()).collect();
        let path = PathBuf::from(&assembly.source);
        let search =
            py.detach(|| SteppedSearch::start_assembly(assembly, &path, &plan, record).map_err(Error::from)).map_err(|e| e.into_py(py))?;
        let index = serde_json::to_string(search.index()).expect("the index serialises");
        Ok(PySearch { inner: Mutex::new(Some(search)), index, swaps: AtomicUsize::new(0) })
    }

    fn lock(&self) -> MutexGuard<'_, Option<SteppedSearch>> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Waits for the search's next report without the GIL, in slices, stopping the search on a
    /// pending signal (then waiting for it to end and raising the signal's exception).
    fn wait(&self, py: Python<'_>, search: &mut SteppedSearch) -> PyResult<Poll> {
        let mut raised: Option<PyErr> = None;
        loop {
            let polled = py.detach(|| search.poll(SIGNAL_INTERVAL));
            match polled {
                Err(e) => return Err(raised.unwrap_or_else(|| Error::from(e).into_py(py))),
                Ok(Poll::Pending) => {}
                // interrupted: the search ends, even when the episode ended by itself meanwhile
                Ok(Poll::Episode(end)) if raised.is_some() && !end.finished => search.request_finish(),
                Ok(p) => {
                    if let Some(e) = raised {
                        return Err(e);
                    }
                    return Ok(p);
                }
            }
            if raised.is_none() {
                if let Err(e) = py.check_signals() {
                    search.stop_token().stop();
                    raised = Some(e);
                }
            }
        }
    }
}

#[pymethods]
impl PySearch {
    /// The `index.json` of the run's transitions as a data set of one model (JSON; counts 0).
    #[getter]
    fn index_json(&self) -> String {
        self.index.clone()
    }

    /// Policies swapped in so far.
    #[getter]
    fn swaps(&self) -> usize {
        self.lock().as_ref().map_or_else(|| self.swaps.load(Ordering::Relaxed), SteppedSearch::swaps)
    }

    /// Whether the search has ended.
    #[getter]
    fn ended(&self) -> bool {
        self.lock().as_ref().is_none_or(SteppedSearch::ended)
    }

    /// Runs the next episode; returns its report.
    fn episode(&self, py: Python<'_>) -> PyResult<EpisodeReport> {
        let mut guard = self.lock();
        let Some(search) = guard.as_mut() else {
            return Err(Error::config("the search has ended and its result was taken").into_py(py));
        };
        search.request_episode().map_err(|e| Error::from(e).into_py(py))?;
        match self.wait(py, search)? {
            Poll::Episode(end) => {
                let mut lines = Vec::new();
                collect_q::write_transition_lines(&mut lines, search.problem(), &end.transitions)
                    .map_err(|e| Error::config(format!("cannot write the transitions: {e}")).into_py(py))?;
                Ok(EpisodeReport {
                    transitions_jsonl: String::from_utf8(lines).expect("JSON is UTF-8"),
                    episodes: end.episodes,
                    iterations: end.iterations,
                    seconds: end.seconds,
                    value: end.value,
                    front_size: end.front_size,
                    finished: end.finished,
                    exhausted: end.exhausted,
                    stopped: end.stopped,
                    capped: end.transitions_capped,
                })
            }
            Poll::Done | Poll::Pending => Err(Error::config("the search has ended: no more episodes").into_py(py)),
        }
    }

    /// Swaps in the ε-greedy policy over the Q models at `paths` (one per objective, in their
    /// order) from the next episode on (`epsilon` and `q_use` default as in `Assembly.plan`).
    #[pyo3(signature = (paths, epsilon=None, q_use=None))]
    fn set_q(&self, py: Python<'_>, paths: Vec<PathBuf>, epsilon: Option<f64>, q_use: Option<&str>) -> PyResult<()> {
        let uses = match q_use {
            None => QUse::default(),
            Some(u) => u.parse().map_err(|e: asp_search::SearchError| Error::config(format!("q_use: {e}")).into_py(py))?,
        };
        let mut guard = self.lock();
        let Some(search) = guard.as_mut() else {
            return Err(Error::config("the search has ended and its result was taken").into_py(py));
        };
        let objectives = search.problem().objective_names();
        let objectives: Vec<&str> = objectives.iter().map(String::as_str).collect();
        let q = QPolicy::new(&paths, &objectives, epsilon.unwrap_or(DEFAULT_EPSILON), uses).map_err(|e| Error::from(e).into_py(py))?;
        let problem = search.problem();
        let policy = py.detach(|| q.prepare(problem)).map_err(|e| Error::from(e).into_py(py))?;
        search.set_policy(policy);
        Ok(())
    }

    /// Ends the search (after the episode running) and returns `(plan_json, found, trace_csv)`
    /// as `Assembly.plan` does.
    fn result(&self, py: Python<'_>) -> PyResult<(String, bool, String)> {
        let mut guard = self.lock();
        let Some(search) = guard.as_mut() else {
            return Err(Error::config("the search's result was taken already").into_py(py));
        };
        search.request_finish();
        loop {
            if let Poll::Done = self.wait(py, search)? {
                break;
            }
        }
        let mut search = guard.take().expect("checked");
        self.swaps.store(search.swaps(), Ordering::Relaxed);
        let result = py.detach(|| search.take_result()).map_err(|e| Error::from(e).into_py(py))?;
        let mut csv = Vec::new();
        if let Some(s) = &result.search {
            s.write_trace_csv(&mut csv).map_err(|e| Error::config(format!("cannot write the trace: {e}")).into_py(py))?;
        }
        Ok((result.report.to_json(), result.found(), String::from_utf8_lossy(&csv).into_owned()))
    }
}
