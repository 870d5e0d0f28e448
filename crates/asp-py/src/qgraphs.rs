//! `asp._asp.QGraphs`: the graphs of optimiser states that learned Q-functions read
//! (`asp_search::qgraph`, features `asp-q/1`), for training in Python. The handle owns the
//! model's distance maps and the MDP built from them, so a state's graph is the same arrays the
//! search's Q-function sees.

use crate::arrays::GraphArrays;
use crate::errors::Error;
use crate::settings;
use asp_app::pipeline::{self, OptimiserProblem};
use asp_geom::distmap::{DirMask, MapState};
use asp_geom::PartSet;
use asp_search::qgraph::{QGraph, QGraphBuilder};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::{Arc, Mutex};

/// The maps and MDP of one model with the graph builder of its states.
#[pyclass(frozen, module = "asp._asp", name = "QGraphs")]
pub struct PyQGraphs {
    problem: OptimiserProblem,
    builder: Mutex<(QGraphBuilder, QGraph)>,
    objectives: Vec<String>,
    reward_ranges: Vec<Option<(f64, f64)>>,
}

impl PyQGraphs {
    /// Builds the maps and the MDP of `assembly` for the keywords of `Assembly.q_graphs`
    /// (without the GIL).
    pub fn build(py: Python<'_>, assembly: Arc<asp_geom::Assembly>, dict: &Bound<'_, PyDict>) -> PyResult<Self> {
        let (plan, optimise, neighbours) = settings::q_graph_settings(dict).map_err(|e| e.into_py(py))?;
        let problem =
            py.detach(|| pipeline::optimiser_problem(&assembly, &plan, &optimise).map_err(Error::from)).map_err(|e| e.into_py(py))?;
        let builder = QGraphBuilder::new(problem.mdp.maps(), neighbours);
        let objectives = problem.mdp.objectives().iter().map(|o| o.name().to_string()).collect();
        let reward_ranges = problem.mdp.objectives().iter().map(|o| o.reward_range(problem.mdp.maps())).collect();
        Ok(PyQGraphs { problem, builder: Mutex::new((builder, QGraph::default())), objectives, reward_ranges })
    }
}

/// Parts as a set of `n`, or a config error naming the keyword.
fn part_set(what: &str, parts: &[i64], n: usize) -> Result<PartSet, Error> {
    let mut set = PartSet::empty(n);
    for &p in parts {
        match usize::try_from(p) {
            Ok(i) if i < n => set.insert(i),
            _ => return Err(Error::config(format!("{what}: no part {p} (the model has {n} parts, 0 to {})", n.saturating_sub(1)))),
        }
    }
    Ok(set)
}

#[pymethods]
impl PyQGraphs {
    /// The features string (`asp-q/1 directions=81 neighbours=8`).
    #[getter]
    fn features(&self) -> String {
        self.lock().0.config().features()
    }

    /// Floats per node.
    #[getter]
    fn node_dim(&self) -> usize {
        self.lock().0.config().node_dim()
    }

    /// Floats per edge.
    #[getter]
    fn edge_dim(&self) -> usize {
        self.lock().0.config().edge_dim()
    }

    /// Directions of the maps (`D`).
    #[getter]
    fn directions(&self) -> usize {
        self.problem.mdp.maps().num_directions()
    }

    /// Parts of the model.
    #[getter]
    fn num_parts(&self) -> usize {
        self.problem.mdp.maps().num_parts()
    }

    /// Parts that are not fixed (`N_r` of the normalised returns).
    #[getter]
    fn removable(&self) -> usize {
        let maps = self.problem.mdp.maps();
        (0..maps.num_parts()).filter(|&i| !maps.is_fixed(i)).count()
    }

    /// The objectives' names.
    #[getter]
    fn objectives(&self) -> Vec<String> {
        self.objectives.clone()
    }

    /// Each objective's per-step reward range `(lo, hi)`, or `None` when it has none.
    #[getter]
    fn reward_ranges(&self) -> Vec<Option<(f64, f64)>> {
        self.reward_ranges.clone()
    }

    /// The feasible removals of the state `present` on the maps: collision-free along some
    /// direction, not fixed, and leaving the rest supported (the filters of extensions, such as
    /// a robot's, are not applied).
    fn feasible_actions(&self, py: Python<'_>, present: Vec<i64>) -> PyResult<Vec<usize>> {
        let maps = self.problem.mdp.maps();
        let set = part_set("present", &present, maps.num_parts()).map_err(|e| e.into_py(py))?;
        let mut state = MapState::new(maps);
        state.reset(&set);
        let mut out = Vec::new();
        state.feasible_actions(&mut out);
        Ok(out)
    }

    /// The graph of the state `present` (part indices) with the `dirchange` history `history`
    /// (direction indices; empty before the first removal) and the feasible `actions` flagged,
    /// as little-endian buffers (the layout of `Assembly.graph`; the context node's part index
    /// is -1).
    #[pyo3(signature = (present, actions=Vec::new(), history=Vec::new()))]
    fn graph<'py>(&self, py: Python<'py>, present: Vec<i64>, actions: Vec<i64>, history: Vec<i64>) -> PyResult<GraphArrays> {
        let maps = self.problem.mdp.maps();
        let n = maps.num_parts();
        let set = part_set("present", &present, n).map_err(|e| e.into_py(py))?;
        let actions_set = part_set("actions", &actions, n).map_err(|e| e.into_py(py))?;
        if let Some(a) = actions_set.iter().find(|&a| !set.contains(a)) {
            return Err(Error::config(format!("actions: part {a} is not present")).into_py(py));
        }
        let d = maps.num_directions();
        let history = if history.is_empty() {
            None
        } else {
            let mut mask = DirMask::EMPTY;
            for &h in &history {
                match usize::try_from(h) {
                    Ok(k) if k < d => mask.insert(k),
                    _ => return Err(Error::config(format!("history: no direction {h} (the maps have {d}, 0 to {})", d - 1)).into_py(py)),
                }
            }
            Some(mask)
        };
        let actions: Vec<usize> = actions_set.iter().collect();
        let mut guard = self.lock();
        let (builder, graph) = &mut *guard;
        let mut state = MapState::new(maps);
        state.reset(&set);
        builder.build(&mut state, history, &actions, graph);
        let config = builder.config();
        Ok(GraphArrays::new(
            py,
            graph.nodes.iter().copied(),
            &graph.x,
            graph.edge_index.iter().copied(),
            &graph.edge_attr,
            config.node_dim(),
            config.edge_dim(),
            config.features(),
        ))
    }

    fn __repr__(&self) -> String {
        format!("<asp._asp.QGraphs {} ({} parts, {})>", self.objectives.join(","), self.num_parts(), self.features())
    }
}

impl PyQGraphs {
    fn lock(&self) -> std::sync::MutexGuard<'_, (QGraphBuilder, QGraph)> {
        self.builder.lock().unwrap_or_else(|e| e.into_inner())
    }
}
