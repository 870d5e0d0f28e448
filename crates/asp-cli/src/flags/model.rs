//! How a model is loaded and its removals tested: the flags shared by `plan`, `collect` and
//! `bench`. Every flag is optional; a flag left out takes the request's default.

use super::Map;
use asp_app::request::{Overlaps, Stability};
use clap::Args;

/// Loading and the removal test.
#[derive(Args, Debug, Clone, Default)]
pub struct ModelArgs {
    /// The unit of the model's coordinates: m, cm, mm, in, ft or metres per unit
    /// [default: m, or what the file says].
    #[arg(long)]
    pub unit: Option<String>,
    /// The up axis: x, y, z, -x, -y, -z [default: +y for glTF, +z for STEP (it has none; most
    /// CAD is Z up) and OBJ/STL, or what the file says].
    #[arg(long)]
    pub up: Option<String>,
    /// Base parts that stay in place (names). Without any, a ground plane under the lowest point
    /// is the base.
    #[arg(long, num_args = 1.., value_name = "NAME")]
    pub fixed: Vec<String>,
    /// Let the model (and a URDF) read files outside its folder: absolute paths, `..` that
    /// climbs out, symlinks that point out (docs/security.md).
    #[arg(long)]
    pub allow_outside_files: bool,
    /// Most triangles a model may have over all its parts.
    #[arg(long, value_name = "N")]
    pub max_triangles: Option<usize>,
    /// Most parts a model may have.
    #[arg(long, value_name = "N")]
    pub max_parts: Option<usize>,
    /// STEP files: the chord tolerance of each edge and face relative to its own size.
    #[arg(long, value_name = "RELATIVE")]
    pub tessellation: Option<f64>,
    /// Make each separate body of a part's mesh (pieces that do not touch, such as shelf pins
    /// stored in a shelf's mesh) a part of its own, named `NAME#1`, `NAME#2`, ...
    #[arg(long)]
    pub split_bodies: bool,
    /// Contact tolerance in model units: motions may push a part this deep into another
    /// [default: 1e-4 × the model's diagonal].
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// Parts closer than this (model units) are in contact for stability [default: 1e-3 × diagonal].
    #[arg(long)]
    pub contact_distance: Option<f64>,
    /// Parts that overlap in the input (warned once per pair with the measured depth).
    #[arg(long, value_parser = super::choice::<Overlaps>())]
    pub overlaps: Option<Overlaps>,
    /// Old spelling of `--overlaps lenient`.
    #[arg(long, hide = true, conflicts_with = "overlaps")]
    pub ignore_overlapping: bool,
    /// Clustered surface-normal directions tried besides the six axes (each with its opposite).
    #[arg(long)]
    pub normals: Option<usize>,
    /// Extra removal directions sampled evenly on the sphere.
    #[arg(long)]
    pub sphere_directions: Option<usize>,
    /// Stability criterion.
    #[arg(long, value_parser = super::choice::<Stability>())]
    pub stability: Option<Stability>,
    /// Physics stability: how far (fraction of the model's diagonal) a part may move in the
    /// simulation before the state counts as unstable.
    #[arg(long)]
    pub physics_threshold: Option<f64>,
    /// Never call the path planner (straight lines only).
    #[arg(long)]
    pub no_path_planner: bool,
    /// Never let a group of parts leave together as one rigid subassembly (single parts only).
    #[arg(long)]
    pub no_subassemblies: bool,
    /// `from-file`: follow the file's product tree: plan each subassembly of the file on its
    /// own, then the level above with each as one unit (a hierarchical plan).
    #[arg(long, value_name = "MODE", value_parser = ["from-file"], conflicts_with = "no_subassemblies")]
    pub subassemblies: Option<String>,
    /// Never plan voxel models by grid moves (interlocking puzzles whose parts must slide in
    /// turn before anything can leave).
    #[arg(long)]
    pub no_grid: bool,
    /// Path planner iterations per call.
    #[arg(long)]
    pub rrt_iterations: Option<usize>,
    /// Path planner wall-time safety cap per call, seconds (the iteration budget keeps runs
    /// reproducible; this only guards against pathological models).
    #[arg(long)]
    pub rrt_time: Option<f64>,
}

impl ModelArgs {
    /// The request keys these flags set.
    pub fn put(&self, map: &mut Map) {
        put!(
            map,
            self,
            unit,
            up,
            max_triangles,
            max_parts,
            tessellation,
            subassemblies,
            tolerance,
            contact_distance,
            overlaps,
            normals,
            sphere_directions,
            stability,
            physics_threshold,
            rrt_iterations,
            rrt_time
        );
        if !self.fixed.is_empty() {
            map.insert("fixed".into(), self.fixed.clone().into());
        }
        for (key, on) in [("allow_outside_files", self.allow_outside_files), ("split_bodies", self.split_bodies)] {
            if on {
                map.insert(key.into(), true.into());
            }
        }
        if self.ignore_overlapping {
            map.insert("overlaps".into(), "lenient".into());
        }
        for (key, off) in [("path_planner", self.no_path_planner), ("subassemblies", self.no_subassemblies), ("grid", self.no_grid)] {
            if off {
                map.insert(key.into(), false.into());
            }
        }
    }
}
