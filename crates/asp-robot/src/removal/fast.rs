//! The planner's collision check of one configuration, and of the samples of an edge: the
//! arm's spheres ([`super::bodies`]) against the parts ([`super::grid`]), the floor and the
//! ground, and the exact test only where a sphere comes near something.
//!
//! A shape is free when its enclosing sphere, else each of its small spheres, stays farther
//! from every present part, the floor and the ground than its radius (a distance from the
//! state's field first, the exact box distances when that is not enough); only a small sphere
//! that does not is followed by the exact test of its shape against what it comes near (the
//! same test as [`RemovalPlanner::shapes_collide`]). Spheres hold every point of their shape,
//! so no collision of the exact test is missed and the verdict is the exact test's (tested on
//! random configurations). The same distances give each shape's clearance, by which a walk
//! along an edge skips the shapes (and the samples) that cannot have met anything yet.

use super::bodies::{Frame, Shape, Spheres};
use super::grid::GridBox;
use super::*;
use crate::spheres::{cover, enclosing, Sphere, SPHERE_PIECE};

/// What one check of [`SphereSpace::check`] found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Found {
    /// The arm or the held part collides.
    Robot,
    /// The arm is free, the held part collides.
    Held,
    /// Everything is free; the clearance bound (0 unless asked for and above `need`).
    Free(f32),
}

/// What one shape (or pair of shapes) came to at one configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Eval {
    /// It collides (exact test).
    Hit,
    /// The held part's spheres come near something: its exact test decides.
    HeldNear,
    /// Free, with a lower bound on how far its points may move before it meets anything.
    Clear(f32),
}

/// Buffers of one check.
#[derive(Debug, Default)]
struct Scratch {
    frames: Vec<Frame>,
    at: Placing,
    /// Boxes already tested exactly against the current shape.
    tested: Vec<u32>,
    /// The configuration of the current sample of an edge.
    q: Vec<f64>,
    /// Per shape, then per self pair: how far it moves per sample of the current edge.
    moves: Vec<f32>,
    /// Per shape, then per self pair: where along the edge it was last evaluated, and its
    /// clearance there.
    last: Vec<(f32, f32)>,
}

/// The world positions of one sample's spheres, computed as they are asked for.
#[derive(Debug, Default)]
struct Placing {
    /// Per shape: whether its small spheres' world centres are in `centres` (this sample).
    placed: Vec<bool>,
    centres: Vec<[f32; 3]>,
    /// Per shape: its enclosing sphere's world centre (NaN: not yet placed this sample).
    bounds: Vec<[f32; 3]>,
}

impl Placing {
    /// Ready for a new sample of `shapes` shapes and `spheres` small spheres.
    fn reset(&mut self, shapes: usize, spheres: usize) {
        self.placed.clear();
        self.placed.resize(shapes, false);
        self.centres.resize(spheres, [0.0; 3]);
        self.bounds.clear();
        self.bounds.resize(shapes, [f32::NAN; 3]);
    }
}

/// What a walk along an edge did: configurations examined (some shape evaluated) and skipped
/// (every shape still within its clearance).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Walk {
    pub(super) examined: u64,
    pub(super) skipped: u64,
}

/// The sphere check of one joint space: the arm at one opening, holding one part with one
/// grasp, among one state's obstacles.
pub(super) struct SphereSpace<'a, W: Borrow<World>> {
    planner: &'a RemovalPlanner<W>,
    obstacles: &'a Obstacles,
    held: usize,
    shrunk: &'a TriMesh,
    grasp_inv: Pose,
    shapes: Vec<Shape>,
    spheres: Spheres,
    /// Index of the held part's enclosing sphere and cover in `shapes` (the last one).
    held_shape: usize,
    ground: Option<GridBox>,
    /// Whether the base (it never moves) collides with an obstacle.
    base_blocked: bool,
    up: [f32; 3],
    floor: f32,
    scratch: std::cell::RefCell<Scratch>,
}

impl<'a, W: Borrow<World>> SphereSpace<'a, W> {
    /// The check of the arm opened to `opening`, holding `held` (shrunk: `shrunk`) with the tool
    /// centre at `grasp` in the assembled pose, among `obstacles`.
    pub(super) fn new(
        planner: &'a RemovalPlanner<W>,
        held: usize,
        shrunk: &'a TriMesh,
        grasp: Pose,
        opening: f32,
        obstacles: &'a Obstacles,
    ) -> Self {
        let model = &planner.model;
        let robot = &planner.cell.robot;
        let world = planner.world();
        let mut shapes = model.shapes.clone();
        let mut spheres = model.spheres.clone();
        // the fingers at this opening: their shapes and spheres moved into the last body
        let max = robot.max_opening().max(f32::MIN_POSITIVE) as f64;
        let frac = (opening as f64 / max).clamp(0.0, 1.0);
        for &(k, f, link_pose) in &model.fingers {
            let finger = &robot.fingers()[f];
            let (lo, hi) = finger.joint.limits;
            let tool = crate::convert::pose_to_na(&model.tool.to_pose());
            let to_body = crate::convert::pose_from_na(&(tool * finger.origin_in_tool * finger.joint.motion(lo + frac * (hi - lo))));
            let p = &planner.arm[k];
            let shape = LinkShape { local_pose: link_pose, kind: p.kind };
            let range = shapes[k].spheres.clone();
            let bound = enclosing(&shape).transformed(&to_body);
            for (i, s) in range.clone().zip(cover(&shape, SPHERE_PIECE)) {
                spheres.set(i, s.transformed(&to_body), &bound);
            }
            shapes[k] = Shape { body: model.steps.len(), local: Frame::from_pose(&(to_body * p.local)), bound, spheres: range };
        }
        // the held part: its boxes shrunk as in the exact test (else its box), in the last body
        let to_body = model.tool.to_pose() * grasp.inverse();
        let first = spheres.len();
        let part_boxes: Vec<Aabb> = match &planner.held_cuboids[held] {
            Some(boxes) => boxes.iter().map(|c| c.aabb).collect(),
            None => vec![*world.shapes().aabb(held)],
        };
        let all = part_boxes.iter().copied().reduce(|a, b| a.merged(&b)).unwrap_or_else(|| *world.shapes().aabb(held));
        let bound =
            Sphere { centre: to_body.transform_point(all.center()), radius: all.half_extents().length() + crate::spheres::SPHERE_SLACK };
        for b in &part_boxes {
            let half = b.half_extents();
            let shape = LinkShape { local_pose: Pose::from_translation(b.center()), kind: ShapeKind::Box { half_extents: half } };
            for s in cover(&shape, SPHERE_PIECE) {
                spheres.push(s.transformed(&to_body), &bound);
            }
        }
        let held_shape = shapes.len();
        shapes.push(Shape { body: model.steps.len(), local: Frame::IDENTITY, bound, spheres: first..spheres.len() });
        let ground = obstacles.ground.map(|g| {
            let b = world.shapes().aabb(g);
            GridBox { mins: b.mins.to_array(), maxs: b.maxs.to_array(), part: g as u32, index: u32::MAX }
        });
        // the base never moves: tested once, exactly
        let base_placed: Vec<(Pose, Aabb)> = {
            let base = crate::convert::pose_from_na(&robot.base);
            let poses = vec![base; planner.base_shapes];
            world_shapes(&planner.arm[..planner.base_shapes], &poses)
        };
        let base_blocked = planner.shapes_collide(&base_placed, 0, obstacles);
        let scratch = Scratch::default();
        SphereSpace {
            planner,
            obstacles,
            held,
            shrunk,
            grasp_inv: grasp.inverse(),
            shapes,
            spheres,
            held_shape,
            ground,
            base_blocked,
            up: planner.cell.up.to_array(),
            floor: planner.cell.floor,
            scratch: std::cell::RefCell::new(scratch),
        }
    }

    /// A lower bound on the distance from `p` to the obstacles (with `floor`: the floor too):
    /// from the state's field (`exact`: false), else the exact box distances near `p`.
    #[inline]
    fn distance(&self, p: [f32; 3], floor: bool, exact: bool) -> f32 {
        let field = &self.obstacles.field;
        let mut d =
            if exact { self.planner.grid.distance_squared(p, &field.present).sqrt() } else { field.distance(&self.planner.grid, p) };
        if let Some(g) = &self.ground {
            d = d.min(g.distance_squared(p).sqrt());
        }
        if floor {
            d = d.min(p[0] * self.up[0] + p[1] * self.up[1] + p[2] * self.up[2] - self.floor);
        }
        d
    }

    /// Whether shape `k` (not the held part), whose sphere at `c` with radius `r` comes near
    /// something, collides with it (the exact test).
    fn exact_near(&self, k: usize, pose: &Pose, c: [f32; 3], r: f32, tested: &mut Vec<u32>) -> bool {
        let planner = self.planner;
        let world = planner.world();
        let shape = &planner.arm[k];
        let floor_gap = c[0] * self.up[0] + c[1] * self.up[1] + c[2] * self.up[2] - self.floor;
        if floor_gap < r && !tested.contains(&u32::MAX) {
            tested.push(u32::MAX);
            if shape.meets(pose, &planner.floor.0, &*planner.floor.1) {
                return true;
            }
        }
        if let Some(g) = &self.ground {
            if g.distance_squared(c) < r * r && !tested.contains(&(u32::MAX - 1)) {
                tested.push(u32::MAX - 1);
                if shape.meets(pose, &Pose::IDENTITY, world.shapes().mesh(g.part as usize)) {
                    return true;
                }
            }
        }
        planner.grid.any_near(c, r, &self.obstacles.field.present, |id, b| {
            if tested.contains(&id) {
                return false;
            }
            tested.push(id);
            let part = b.part as usize;
            match (&planner.cuboids[part], b.index) {
                (Some(boxes), i) if i != u32::MAX => {
                    let c = &boxes[i as usize];
                    shape.meets(pose, &c.centre, &c.cuboid)
                }
                _ => shape.meets(pose, &Pose::IDENTITY, world.shapes().mesh(part)),
            }
        })
    }

    /// Places shape `k`'s small spheres (world centres into `at.centres`, once per sample).
    #[inline]
    fn place(&self, k: usize, frames: &[Frame], at: &mut Placing) {
        if at.placed[k] {
            return;
        }
        let f = &frames[self.shapes[k].body];
        let s = &self.spheres;
        for i in self.shapes[k].spheres.clone() {
            at.centres[i] = f.point([s.x[i], s.y[i], s.z[i]]);
        }
        at.placed[k] = true;
    }

    /// Shape `k`'s enclosing sphere's world centre (once per sample: the shape and each of its
    /// self pairs ask for it).
    #[inline]
    fn bound_centre(&self, k: usize, frames: &[Frame], at: &mut Placing) -> [f32; 3] {
        let b = at.bounds[k];
        if !b[0].is_nan() {
            return b;
        }
        let shape = &self.shapes[k];
        let b = frames[shape.body].point(shape.bound.centre.to_array());
        at.bounds[k] = b;
        b
    }

    /// Shape `k` against the obstacles (the arm's shapes against the floor too) at the body
    /// frames `frames`: its enclosing sphere, else its small spheres (those the enclosing
    /// sphere's clearance does not already clear), else the exact test where one comes near.
    fn eval_shape(&self, k: usize, frames: &[Frame], at: &mut Placing, tested: &mut Vec<u32>) -> Eval {
        let shape = &self.shapes[k];
        let f = &frames[shape.body];
        let b = self.bound_centre(k, frames, at);
        let is_held = k == self.held_shape;
        // the field's bound, then the exact box distances
        let mut d = self.distance(b, !is_held, false);
        if d < shape.bound.radius {
            d = self.distance(b, !is_held, true);
        }
        if d >= shape.bound.radius {
            return Eval::Clear(d - shape.bound.radius);
        }
        let mut clearance = f32::INFINITY;
        let mut pose = None;
        // whether every small sphere's centre is placed (a sphere the enclosing one's clearance
        // clears is not; a self pair of this shape then places them all)
        let mut all = true;
        tested.clear();
        let s = &self.spheres;
        for i in shape.spheres.clone() {
            let r = s.r[i];
            // within the enclosing sphere's clearance less its distance from the centre
            let slack = d - s.off[i] - r;
            if slack >= 0.0 {
                clearance = clearance.min(slack);
                all = false;
                continue;
            }
            let c = f.point([s.x[i], s.y[i], s.z[i]]);
            at.centres[i] = c;
            let mut di = self.distance(c, !is_held, false);
            if di < r {
                di = self.distance(c, !is_held, true);
            }
            if di >= r {
                clearance = clearance.min(di - r);
                continue;
            }
            if is_held {
                // the held part's exact test covers every obstacle at once
                return Eval::HeldNear;
            }
            clearance = 0.0;
            let pose = *pose.get_or_insert_with(|| f.mul(&shape.local).to_pose());
            if self.exact_near(k, &pose, c, r, tested) {
                return Eval::Hit;
            }
        }
        at.placed[k] = all;
        Eval::Clear(clearance)
    }

    /// Self pair `p` ([`RemovalPlanner::self_pairs`]) at the body frames `frames`: enclosing
    /// spheres, small spheres, then the exact test.
    fn eval_pair(&self, p: usize, frames: &[Frame], at: &mut Placing) -> Eval {
        let (i, j) = self.planner.self_pairs[p];
        let (si, sj) = (&self.shapes[i], &self.shapes[j]);
        let (bi, bj) = (self.bound_centre(i, frames, at), self.bound_centre(j, frames, at));
        let gap = dist(bi, bj) - si.bound.radius - sj.bound.radius;
        if gap > 0.0 {
            return Eval::Clear(gap);
        }
        self.place(i, frames, at);
        self.place(j, frames, at);
        let rs = &self.spheres.r;
        let centres = &at.centres;
        let mut gap = f32::INFINITY;
        for a in si.spheres.clone() {
            // the small sphere against the other shape's enclosing one, then its small ones
            let whole = dist(centres[a], bj) - rs[a] - sj.bound.radius;
            if whole > 0.0 {
                gap = gap.min(whole);
                continue;
            }
            for b in sj.spheres.clone() {
                gap = gap.min(dist(centres[a], centres[b]) - rs[a] - rs[b]);
            }
        }
        if gap > 0.0 {
            return Eval::Clear(gap);
        }
        let (pi, pj) = (frames[si.body].mul(&si.local).to_pose(), frames[sj.body].mul(&sj.local).to_pose());
        if self.planner.arm[i].meets_prepared(&pi, &self.planner.arm[j], &pj) {
            Eval::Hit
        } else {
            Eval::Clear(0.0)
        }
    }

    /// The held part's exact test at the body frames `frames`.
    fn held_hits(&self, frames: &[Frame]) -> bool {
        let tool = frames[frames.len() - 1].mul(&self.planner.model.tool).to_pose();
        self.planner.held_collides(self.held, self.shrunk, &(tool * self.grasp_inv), self.obstacles)
    }

    /// The shapes tested against the obstacles: all but the base's (it never moves; tested once).
    fn moving(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.shapes.len()).filter(|&k| self.shapes[k].body != 0)
    }

    /// Checks the arm at `q`: the base's verdict, every moving shape and the held part against
    /// the obstacles (and the floor, the arm only), the arm against itself; with `need`, the
    /// clearance bound too (see [`Found::Free`]).
    pub(super) fn check(&self, q: &[f64], need: Option<f32>) -> Found {
        if self.base_blocked {
            return Found::Robot;
        }
        let mut guard = self.scratch.borrow_mut();
        let Scratch { frames, at, tested, .. } = &mut *guard;
        self.planner.model.body_frames(q, frames);
        at.reset(self.shapes.len(), self.spheres.len());
        let mut clearance = f32::INFINITY;
        let mut held_near = false;
        for k in self.moving() {
            match self.eval_shape(k, frames, at, tested) {
                Eval::Hit => return Found::Robot,
                Eval::HeldNear => held_near = true,
                Eval::Clear(c) => clearance = clearance.min(c),
            }
        }
        if self.planner.config.self_collision {
            for p in 0..self.planner.self_pairs.len() {
                match self.eval_pair(p, frames, at) {
                    Eval::Hit => return Found::Robot,
                    Eval::HeldNear => {}
                    Eval::Clear(c) => clearance = clearance.min(c),
                }
            }
        }
        if held_near {
            if self.held_hits(frames) {
                return Found::Held;
            }
            clearance = 0.0;
        }
        match need {
            Some(need) if clearance >= need => Found::Free(clearance),
            _ => Found::Free(0.0),
        }
    }

    /// Whether the samples `a + (b − a) i/n`, `i = 1..n`, are collision-free (`a` and `b` are).
    /// `reach[b]` bounds how far a point of body `b` moves between two samples (the joints
    /// before it, by their lever arms); a pair of bodies moves against each other by the
    /// difference. Each shape and self pair is evaluated only once the edge may have moved it
    /// as far as its clearance when last evaluated; a sample where none is due is skipped (no
    /// kinematics either).
    pub(super) fn edge_free(&self, a: &[f64], b: &[f64], n: usize, reach: &[f64], walk: &mut Walk) -> bool {
        if self.base_blocked {
            return false;
        }
        let mut guard = self.scratch.borrow_mut();
        let Scratch { frames, at, tested, q, last, moves } = &mut *guard;
        let pairs = if self.planner.config.self_collision { self.planner.self_pairs.len() } else { 0 };
        let shapes = self.shapes.len();
        // how far each shape, then each pair, moves per sample
        moves.clear();
        moves.extend((0..shapes).map(|k| reach[self.shapes[k].body] as f32));
        moves.extend(self.planner.self_pairs[..pairs].iter().map(|&(i, j)| {
            let (x, y) = (self.shapes[i].body, self.shapes[j].body);
            (reach[x.max(y)] - reach[x.min(y)]) as f32
        }));
        last.clear();
        last.resize(shapes + pairs, (0.0, -1.0));
        for i in 1..n {
            let at_i = i as f32;
            // shape k (or pair) is clear here when it was `c` clear at sample `s` and has moved
            // less than `c` since
            let due = |x: &(f32, f32), m: f32| (at_i - x.0) * m >= x.1;
            if !(0..shapes + pairs).any(|k| (k >= shapes || self.shapes[k].body != 0) && due(&last[k], moves[k])) {
                walk.skipped += 1;
                continue;
            }
            walk.examined += 1;
            let t = i as f64 / n as f64;
            q.clear();
            q.extend(a.iter().zip(b).map(|(x, y)| x + (y - x) * t));
            self.planner.model.body_frames(q, frames);
            at.reset(shapes, self.spheres.len());
            let mut held_near = false;
            for k in self.moving() {
                if !due(&last[k], moves[k]) {
                    continue;
                }
                match self.eval_shape(k, frames, at, tested) {
                    Eval::Hit => return false,
                    Eval::HeldNear => {
                        held_near = true;
                        last[k] = (at_i, 0.0);
                    }
                    Eval::Clear(c) => last[k] = (at_i, c),
                }
            }
            for p in 0..pairs {
                if !due(&last[shapes + p], moves[shapes + p]) {
                    continue;
                }
                match self.eval_pair(p, frames, at) {
                    Eval::Hit => return false,
                    Eval::HeldNear => {}
                    Eval::Clear(c) => last[shapes + p] = (at_i, c),
                }
            }
            if held_near && self.held_hits(frames) {
                return false;
            }
        }
        true
    }
}

#[inline(always)]
fn dist(a: [f32; 3], b: [f32; 3]) -> f32 {
    let (x, y, z) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    (x * x + y * y + z * z).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use asp_geom::WorldConfig;
    use rand::SeedableRng;

    /// After a check, every shape counted as placed has every small sphere where this
    /// configuration puts it (a self pair trusts them; the shape's own test skips the spheres
    /// its enclosing sphere clears, and once counted the shape placed anyway, so its pairs read
    /// centres of an earlier configuration).
    #[test]
    fn a_shape_counted_as_placed_has_every_sphere_where_this_configuration_puts_it() {
        let assembly = asp_gen::ProfileAssembly::generate(&asp_gen::ProfileParams::single_layer(), 3).unwrap().to_assembly("p");
        let world = World::new(assembly, &WorldConfig::default()).unwrap();
        let cell = RobotCell::for_assembly(world.assembly(), Robot::panda(), None, None);
        let planner = RemovalPlanner::new(&world, cell, RemovalConfig::default());
        let n = world.num_parts();
        let held = (0..n).find(|&p| !world.contacts().fixed().contains(p)).unwrap();
        let grasp = planner.grasps(held)[0].clone();
        let present = PartSet::full(n);
        let obstacles = planner.obstacles(&present, held);
        let shrunk = world.shapes().eroded(held, planner.config.margin.max(world.shapes().tolerance()));
        let space = SphereSpace::new(&planner, held, &shrunk, Pose::from_parts(grasp.position, grasp.orientation), grasp.width, &obstacles);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let (mut partly, mut checked) = (0, 0);
        for _ in 0..3000 {
            let q = planner.cell.robot.random_configuration(&mut rng);
            space.check(&q, None);
            let scratch = space.scratch.borrow();
            for (k, shape) in space.shapes.iter().enumerate() {
                if !scratch.at.placed.get(k).copied().unwrap_or(false) {
                    continue;
                }
                checked += 1;
                let f = &scratch.frames[shape.body];
                let s = &space.spheres;
                let stale = shape.spheres.clone().filter(|&i| {
                    let c = f.point([s.x[i], s.y[i], s.z[i]]);
                    let d = scratch.at.centres[i];
                    (c[0] - d[0]).abs() + (c[1] - d[1]).abs() + (c[2] - d[2]).abs() > 1e-6
                });
                let stale = stale.count();
                partly += (stale > 0) as usize;
                assert_eq!(stale, 0, "shape {k}: {stale} of its spheres are not where {q:?} puts them");
            }
        }
        assert!(checked > 100, "only {checked} shapes were placed: the test shows little");
        assert_eq!(partly, 0);
    }
}
