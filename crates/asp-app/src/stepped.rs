//! A stepped optimiser run: the search of `asp plan --objective` ([`pipeline::optimise_problem`],
//! the same loop and report), run episode by episode on its own thread while the caller decides
//! between episodes — run the next one, swap the policy (Q-functions retrained on the transitions
//! so far: thesis 6.5's online and retrained settings), or end. The tree stays between episodes.
//! Python's `asp.Assembly.search` and `python -m asp.train q-online` drive it.
//!
//! The search is deterministic: the same model, settings, seed and sequence of policies give the
//! same episodes and the same answer, and with no swap the answer is `asp plan --objective`'s
//! with one thread (a test holds it to that).
//!
//! ```no_run
//! # use asp_app::stepped::{SteppedSearch, Poll};
//! # use asp_app::pipeline::{OptimiseSettings, PlanSettings};
//! # use std::path::Path;
//! let o = OptimiseSettings { objectives: vec!["access".into()], ..OptimiseSettings::default() };
//! let plan = PlanSettings { optimise: Some(o), ..PlanSettings::default() };
//! let mut search = SteppedSearch::start(Path::new("cube.glb"), &plan, true).unwrap();
//! for _ in 0..10 {
//!     let end = search.episode().unwrap();
//!     println!("{} transitions, front {}", end.transitions.len(), end.value);
//!     if end.finished { break; }
//! }
//! let result = search.finish().unwrap();
//! ```

use crate::collect::ModelItem;
use crate::collect_q::{self, TransitionsIndex};
use crate::error::{AppError, Result};
use crate::pipeline::{self, OptimiseSettings, PlanResult, PlanSettings};
use asp_search::Mdp;
use asp_search::Policy;
use asp_search::{EpisodeEnd, Next, StopToken};
use std::path::Path;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// What the search thread sends back.
enum Message {
    Episode(EpisodeEnd),
    Done(Box<Result<PlanResult>>),
}

/// What [`SteppedSearch::poll`] found.
#[derive(Debug)]
pub enum Poll {
    /// Nothing yet (the episode is still running).
    Pending,
    /// The episode asked for ended.
    Episode(EpisodeEnd),
    /// The search ended and its answer is ready ([`SteppedSearch::finish`]).
    Done,
}

/// A search run episode by episode on its own thread (see the module documentation).
pub struct SteppedSearch {
    commands: Sender<Next>,
    messages: Receiver<Message>,
    thread: Option<JoinHandle<()>>,
    stop: StopToken,
    index: TransitionsIndex,
    problem: Arc<Mdp>,
    /// A policy to swap in before the next episode.
    pending_policy: Option<Arc<dyn Policy>>,
    /// An episode was asked for and has not been reported.
    waiting: bool,
    /// The last episode was reported (no more episodes).
    ended: bool,
    result: Option<Result<PlanResult>>,
    swaps: usize,
}

impl std::fmt::Debug for SteppedSearch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SteppedSearch").field("ended", &self.ended).field("swaps", &self.swaps).finish_non_exhaustive()
    }
}

impl SteppedSearch {
    /// Loads the model at `path` and builds its optimiser problem with `settings` (whose
    /// `optimise` must be set: objectives, budget, seed, ε-greedy policy, time limit, ...; the
    /// search runs on one thread and its `episodes` are the most it runs), then waits for
    /// [`episode`](Self::episode). With `record` every episode's transitions are recorded.
    pub fn start(path: &Path, settings: &PlanSettings, record: bool) -> Result<Self> {
        let assembly = Arc::new(pipeline::load(path, settings)?);
        Self::start_assembly(assembly, path, settings, record)
    }

    /// [`start`](Self::start) on a loaded assembly (`path` names it in the index).
    pub fn start_assembly(assembly: Arc<asp_geom::Assembly>, path: &Path, settings: &PlanSettings, record: bool) -> Result<Self> {
        let Some(o) = settings.optimise.clone() else {
            return Err(AppError::config("a stepped search needs objectives (the optimiser's settings)"));
        };
        let o = OptimiseSettings { pareto: o.pareto || o.objectives.len() > 1, threads: Some(1), ..o };
        let stop = settings.cancel.clone().unwrap_or_default();
        let settings = PlanSettings { cancel: Some(stop.clone()), ..settings.clone() };
        let problem = pipeline::optimiser_problem(&assembly, &settings, &o)?;
        let item = ModelItem { path: path.to_path_buf(), index: 0, name: model_name(path), dir: "model".into() };
        let index = collect_q::stepped_index(&item, &settings, &o, &problem.mdp, o.episodes)?;
        let shared = Arc::new(problem.mdp.clone());
        let (commands, inbox) = mpsc::channel::<Next>();
        let (outbox, messages) = mpsc::channel::<Message>();
        let thread = std::thread::Builder::new()
            .name("asp-stepped".into())
            .stack_size(8 << 20)
            .spawn(move || {
                // the first command starts the first episode (or ends the search before it)
                let o = match inbox.recv() {
                    Ok(Next::Continue) => o,
                    Ok(Next::Policy(p)) => OptimiseSettings { policy: Some(Arc::new(crate::catalogue::FixedPolicy(p))), ..o },
                    Ok(Next::Stop) | Err(_) => {
                        let _ = outbox
                            .send(Message::Done(Box::new(Err(AppError::config("the stepped search ended before its first episode")))));
                        return;
                    }
                };
                let reports = outbox.clone();
                let mut hook = move |end: EpisodeEnd| -> asp_search::Result<Next> {
                    let last = end.finished;
                    if reports.send(Message::Episode(end)).is_err() {
                        return Ok(Next::Stop); // the handle is gone
                    }
                    if last {
                        return Ok(Next::Stop);
                    }
                    Ok(inbox.recv().unwrap_or(Next::Stop))
                };
                let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    pipeline::optimise_problem(assembly, &settings, &o, problem, Some(&mut hook), record)
                }))
                .unwrap_or_else(|_| Err(AppError::plugin("stepped search", "panicked")));
                let _ = outbox.send(Message::Done(Box::new(result)));
            })
            .map_err(|e| AppError::config(format!("cannot start the search thread: {e}")))?;
        Ok(SteppedSearch {
            commands,
            messages,
            thread: Some(thread),
            stop,
            index,
            problem: shared,
            pending_policy: None,
            waiting: false,
            ended: false,
            result: None,
            swaps: 0,
        })
    }

    /// The `index.json` of the run's transitions as a data set of one model (`dir` `model`;
    /// the counts are 0: whoever writes the episodes' lines updates them).
    pub fn index(&self) -> &TransitionsIndex {
        &self.index
    }

    /// The problem (maps, objectives) the search runs on.
    pub fn problem(&self) -> &Mdp {
        &self.problem
    }

    /// The token that stops the running episode (Ctrl-C); the search then ends.
    pub fn stop_token(&self) -> &StopToken {
        &self.stop
    }

    /// Policies swapped in so far ([`set_policy`](Self::set_policy) before an episode).
    pub fn swaps(&self) -> usize {
        self.swaps
    }

    /// Whether the search has ended (its root explored, its time or episodes used up, stopped).
    pub fn ended(&self) -> bool {
        self.ended
    }

    /// The policy the next episodes use (e.g. ε-greedy over Q-functions retrained on the
    /// transitions so far); it takes effect at the next episode.
    pub fn set_policy(&mut self, policy: Arc<dyn Policy>) {
        self.pending_policy = Some(policy);
    }

    /// Starts the next episode without waiting for it ([`poll`](Self::poll) for its end).
    pub fn request_episode(&mut self) -> Result<()> {
        if self.ended {
            return Err(AppError::config("the search has ended: no more episodes"));
        }
        if self.waiting {
            return Ok(());
        }
        let command = match self.pending_policy.take() {
            Some(p) => {
                self.swaps += 1;
                Next::Policy(p)
            }
            None => Next::Continue,
        };
        self.waiting = true;
        if self.commands.send(command).is_err() {
            self.ended = true;
        }
        Ok(())
    }

    /// Waits up to `timeout` for the episode asked for (or the search's end).
    pub fn poll(&mut self, timeout: Duration) -> Result<Poll> {
        if self.result.is_some() {
            return Ok(Poll::Done);
        }
        match self.messages.recv_timeout(timeout) {
            Err(RecvTimeoutError::Timeout) => Ok(Poll::Pending),
            Err(RecvTimeoutError::Disconnected) => {
                self.ended = true;
                self.result = Some(Err(AppError::plugin("stepped search", "its thread ended without an answer")));
                Ok(Poll::Done)
            }
            Ok(Message::Episode(end)) => {
                self.waiting = false;
                self.ended |= end.finished;
                Ok(Poll::Episode(end))
            }
            Ok(Message::Done(result)) => {
                self.waiting = false;
                self.ended = true;
                let failed = result.as_ref().as_ref().err().map(|e| e.to_string());
                self.result = Some(*result);
                match failed {
                    // a plug-in's error surfaces at once (and again from finish)
                    Some(message) => Err(AppError::plugin("stepped search", message)),
                    None => Ok(Poll::Done),
                }
            }
        }
    }

    /// Runs the next episode and returns what it did (blocking).
    pub fn episode(&mut self) -> Result<EpisodeEnd> {
        self.request_episode()?;
        loop {
            match self.poll(Duration::from_secs(3600))? {
                Poll::Pending => {}
                Poll::Episode(end) => return Ok(end),
                Poll::Done => return Err(AppError::config("the search has ended: no more episodes")),
            }
        }
    }

    /// Asks the search to end after the episode running (if any), without waiting.
    pub fn request_finish(&mut self) {
        if !self.ended || self.waiting {
            let _ = self.commands.send(Next::Stop);
        }
    }

    /// Ends the search (after the episode running, if any) and returns its answer: the plan
    /// `asp plan --objective` would write for the episodes run.
    pub fn finish(mut self) -> Result<PlanResult> {
        self.request_finish();
        loop {
            if let Poll::Done = self.poll(Duration::from_secs(3600)).unwrap_or(Poll::Done) {
                break;
            }
        }
        self.take_result()
    }

    /// The answer once [`poll`](Self::poll) said [`Poll::Done`] (an error before).
    pub fn take_result(&mut self) -> Result<PlanResult> {
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        self.result.take().unwrap_or_else(|| Err(AppError::config("the search has not ended (or its answer was taken)")))
    }
}

impl Drop for SteppedSearch {
    fn drop(&mut self) {
        self.stop.stop();
        let _ = self.commands.send(Next::Stop);
        if let Some(t) = self.thread.take() {
            // drain so that the thread's sends never block (they do not: the channel is unbounded)
            let _ = t.join();
        }
    }
}

/// The model's name in the index: its file or folder name.
fn model_name(path: &Path) -> String {
    path.file_stem().or_else(|| path.file_name()).map_or_else(|| "model".into(), |n| n.to_string_lossy().into_owned())
}
