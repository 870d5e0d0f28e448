//! The construction of one profile assembly (the module documentation of [`super`] says how):
//! the base cuboid, supports, layers, back and front profiles, each laid, split and connected.

use super::*;

/// A free stretch of a line between the profiles it crosses.
#[derive(Clone, Copy, Debug)]
struct Segment {
    lo: f64,
    hi: f64,
    /// The profile that ends the stretch at `lo` / `hi` (None at the line's end).
    lo_end: Option<usize>,
    hi_end: Option<usize>,
}

impl Segment {
    fn length(&self) -> f64 {
        self.hi - self.lo
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Side {
    Back,
    Front,
}

pub(super) struct Builder<'p> {
    pub(super) p: &'p ProfileParams,
    pub(super) profiles: Vec<Profile>,
    pub(super) connectors: Vec<Connector>,
    /// The last wall thickness of every profile end that meets another profile.
    pub(super) end_slabs: Vec<Cuboid>,
}

impl Builder<'_> {
    /// The centre height of the bottom profiles: they rest on the floor plates of their
    /// connectors, one wall thickness above the ground.
    fn bottom_plane(&self) -> f64 {
        self.p.connector_thickness + self.p.profile_size / 2.0
    }

    /// Length of a profile laid on `seg`: one wall thickness shorter at every end that meets
    /// another profile, where the connector's end plate sits.
    fn held_length(&self, seg: &Segment) -> f64 {
        let t = self.p.connector_thickness;
        seg.length() - t * (seg.lo_end.is_some() as u8 + seg.hi_end.is_some() as u8) as f64
    }

    fn extent(&self, axis: usize) -> f64 {
        [self.p.length, self.p.width, self.p.height][axis]
    }

    /// The box of a profile along `axis` through point `at` (its `axis` coordinate ignored).
    fn profile_box(&self, axis: usize, at: [f64; 3], lo: f64, hi: f64) -> Cuboid {
        let h = self.p.profile_size / 2.0;
        let mut b = Cuboid::new(at.map(|v| v - h), at.map(|v| v + h));
        (b.mins[axis], b.maxs[axis]) = (lo, hi);
        b
    }

    pub(super) fn build(&mut self, rng: &mut ChaCha8Rng) -> std::result::Result<(), String> {
        let (d, l, w, h) = (self.p.profile_size, self.p.length, self.p.width, self.p.height);
        // base: posts first, so the horizontal profiles split against them
        for x in [d / 2.0, l - d / 2.0] {
            for y in [d / 2.0, w - d / 2.0] {
                let post = Segment { lo: 0.0, hi: h, lo_end: None, hi_end: None };
                self.add(2, [x, y, 0.0], post, Role::Base, None, x > l / 2.0)?;
            }
        }
        for (z, fixed) in [(self.bottom_plane(), true), (h - d / 2.0, false)] {
            self.frame(z, Role::Base, None, fixed)?;
        }
        let supports = self.supports(rng)?;
        for layer in 0..self.p.layers {
            self.layer(layer, &supports, rng)?;
        }
        Ok(())
    }

    /// Four profiles along the outline at height `z`, between the corner posts.
    fn frame(&mut self, z: f64, role: Role, layer: Option<usize>, fixed: bool) -> std::result::Result<(), String> {
        let (d, l, w) = (self.p.profile_size, self.p.length, self.p.width);
        let lines = [(0, [0.0, d / 2.0, z]), (0, [0.0, w - d / 2.0, z]), (1, [d / 2.0, 0.0, z]), (1, [l - d / 2.0, 0.0, z])];
        for (axis, at) in lines {
            let seg = self.segments(axis, at).into_iter().find(|s| s.lo_end.is_some() && s.hi_end.is_some());
            let seg = seg.ok_or("the outline is blocked")?;
            self.add(axis, at, seg, role, layer, fixed)?;
        }
        Ok(())
    }

    /// Places the supports with their bottom and top connections; returns their indices.
    fn supports(&mut self, rng: &mut ChaCha8Rng) -> std::result::Result<Vec<usize>, String> {
        let (d, l, w, h) = (self.p.profile_size, self.p.length, self.p.width, self.p.height);
        let (eps_p, k) = (self.p.min_length, self.p.supports);
        let mut spots: Vec<[f64; 2]> = Vec::new();
        for i in 0..k {
            let y_lo = eps_p.max(w * i as f64 / k as f64);
            let y_hi = (w - eps_p).min(w * (i + 1) as f64 / k as f64);
            let spot = [rng.random_range(eps_p..=l - eps_p), rng.random_range(y_lo..=y_hi)];
            let clear = spots.iter().all(|s| (s[0] - spot[0]).hypot(s[1] - spot[1]) >= self.p.grasp_clearance);
            if !clear {
                return Err("supports closer than the grasp clearance".into());
            }
            spots.push(spot);
        }
        let mut supports = Vec::new();
        for [x, y] in spots {
            let mut ends = [0; 2];
            for (end, (z, fixed)) in ends.iter_mut().zip([(self.bottom_plane(), true), (h - d / 2.0, false)]) {
                *end = (0..TRIES_PER_PROFILE)
                    .find_map(|_| {
                        let axis = rng.random_range(0..2);
                        let at = [x, y, z];
                        if !self.clear_of_parallels(axis, at) {
                            return None;
                        }
                        let foot = [x, y][axis];
                        let seg = self
                            .segments(axis, at)
                            .into_iter()
                            .find(|s| s.lo <= foot - d / 2.0 + TOLERANCE && s.hi >= foot + d / 2.0 - TOLERANCE)?;
                        if self.held_length(&seg) < eps_p || seg.lo_end.is_none() || seg.hi_end.is_none() {
                            return None;
                        }
                        self.add(axis, at, seg, Role::SupportConnection, None, fixed).ok()
                    })
                    .ok_or("no room for a support connection")?;
            }
            let bottom = self.profiles[ends[0]].cuboid.maxs[2];
            let seg = Segment { lo: bottom, hi: h - d, lo_end: Some(ends[0]), hi_end: Some(ends[1]) };
            supports.push(self.add(2, [x, y, 0.0], seg, Role::Support, None, false)?);
        }
        Ok(supports)
    }

    fn layer(&mut self, layer: usize, supports: &[usize], rng: &mut ChaCha8Rng) -> std::result::Result<(), String> {
        let z = self.p.layer_height(layer);
        self.frame(z, Role::Frame, Some(layer), false)?;
        let xs: Vec<f64> = supports.iter().map(|&s| self.profiles[s].centre()[0]).collect();
        let x_front = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let x_back = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut connected = vec![false; supports.len()];
        let sides = std::iter::repeat_n(Side::Back, self.p.back).chain(std::iter::repeat_n(Side::Front, self.p.front));
        for (n, side) in sides.enumerate() {
            let placed =
                (0..TRIES_PER_PROFILE).find_map(|_| self.try_layer_profile(side, z, layer, (x_front, x_back), supports, &connected, rng));
            let index = placed.ok_or_else(|| format!("no room for layer profile {} of layer {}", n + 1, layer + 1))?;
            let p = &self.profiles[index];
            for (k, &s) in supports.iter().enumerate() {
                connected[k] |= p.cuboid.touches(&self.profiles[s].cuboid, TOLERANCE);
            }
        }
        Ok(())
    }

    /// One draw of a back or front profile (thesis 4.1.3); None when it has to be drawn again.
    #[allow(clippy::too_many_arguments)]
    fn try_layer_profile(
        &mut self,
        side: Side,
        z: f64,
        layer: usize,
        (x_front, x_back): (f64, f64),
        supports: &[usize],
        connected: &[bool],
        rng: &mut ChaCha8Rng,
    ) -> Option<usize> {
        let (d, l, w, eps_g) = (self.p.profile_size, self.p.length, self.p.width, self.p.grasp_clearance);
        let axis = rng.random_range(0..2);
        let across = 1 - axis;
        let unconnected: Vec<usize> = (0..supports.len()).filter(|&k| !connected[k]).collect();
        let coordinate = if !unconnected.is_empty() && rng.random_bool(0.5) {
            let &k = unconnected.choose(rng)?;
            self.profiles[supports[k]].centre()[across]
        } else {
            let (lo, hi) = match (axis, side) {
                (0, _) => (d / 2.0 + eps_g, w - d / 2.0 - eps_g),
                (_, Side::Back) => (x_front, l - d / 2.0 - eps_g),
                (_, Side::Front) => (d / 2.0 + eps_g, x_back),
            };
            if lo > hi {
                return None;
            }
            rng.random_range(lo..=hi)
        };
        let mut at = [0.0, 0.0, z];
        at[across] = coordinate;
        if !self.clear_of_parallels(axis, at) {
            return None;
        }
        let allowed = |s: &Segment| match (side, axis) {
            (Side::Back, 0) => s.lo >= x_front - TOLERANCE,
            (Side::Back, _) => coordinate >= x_front - TOLERANCE,
            (Side::Front, 0) => s.hi <= x_back + TOLERANCE,
            (Side::Front, _) => coordinate <= x_back + TOLERANCE,
        };
        let segments: Vec<Segment> = self
            .segments(axis, at)
            .into_iter()
            .filter(|s| s.lo_end.is_some() && s.hi_end.is_some() && allowed(s))
            .filter(|s| self.held_length(s) >= self.p.min_length)
            .collect();
        let &seg = segments.choose(rng)?;
        let role = if side == Side::Back { Role::Back } else { Role::Front };
        self.add(axis, at, seg, role, Some(layer), false).ok()
    }

    /// Whether a profile along `axis` through `at` keeps ε_g from every parallel profile.
    fn clear_of_parallels(&self, axis: usize, at: [f64; 3]) -> bool {
        self.profiles.iter().filter(|p| p.axis == axis).all(|p| {
            let c = p.centre();
            let dist2: f64 = (0..3).filter(|&b| b != axis).map(|b| (c[b] - at[b]).powi(2)).sum();
            dist2.sqrt() >= self.p.grasp_clearance - TOLERANCE
        })
    }

    /// The free stretches of the full-length line along `axis` through `at`, between the
    /// profiles it crosses.
    fn segments(&self, axis: usize, at: [f64; 3]) -> Vec<Segment> {
        let line = self.profile_box(axis, at, 0.0, self.extent(axis));
        let mut hits: Vec<(f64, f64, usize)> = self
            .profiles
            .iter()
            .enumerate()
            .filter(|(_, p)| p.cuboid.overlaps(&line, TOLERANCE))
            .map(|(i, p)| (p.cuboid.mins[axis], p.cuboid.maxs[axis], i))
            .collect();
        hits.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
        let mut out = Vec::new();
        let (mut cursor, mut cursor_end) = (0.0, None);
        for (lo, hi, i) in hits {
            if lo > cursor + TOLERANCE {
                out.push(Segment { lo: cursor, hi: lo, lo_end: cursor_end, hi_end: Some(i) });
            }
            if hi > cursor {
                (cursor, cursor_end) = (hi, Some(i));
            }
        }
        if self.extent(axis) > cursor + TOLERANCE {
            out.push(Segment { lo: cursor, hi: self.extent(axis), lo_end: cursor_end, hi_end: None });
        }
        out
    }

    /// Adds the profile on `seg` with a connector at each end that meets another profile,
    /// unless something overlaps; returns its index.
    fn add(
        &mut self,
        axis: usize,
        at: [f64; 3],
        seg: Segment,
        role: Role,
        layer: Option<usize>,
        fixed: bool,
    ) -> std::result::Result<usize, String> {
        // horizontal profiles stop one wall short of what they meet; vertical ones stand on it
        let inset = |end: Option<usize>| if end.is_some() && axis != 2 { self.p.connector_thickness } else { 0.0 };
        let (lo, hi) = (seg.lo + inset(seg.lo_end), seg.hi - inset(seg.hi_end));
        let profile = Profile { axis, cuboid: self.profile_box(axis, at, lo, hi), role, layer, fixed };
        let index = self.profiles.len();
        // every end meets exactly one profile (else its connector would hold on to two), and
        // the new profile touches no end of another
        if self.end_slabs.iter().any(|slab| slab.touches(&profile.cuboid, TOLERANCE)) {
            return Err(format!("a {role:?} profile touches the end of another"));
        }
        let mut connectors = Vec::new();
        let mut slabs = Vec::new();
        for (end, other) in [(seg.lo, seg.lo_end), (seg.hi, seg.hi_end)] {
            if let Some(attached_to) = other {
                let mut slab = profile.cuboid;
                let t = self.p.connector_thickness;
                (slab.mins[axis], slab.maxs[axis]) = if end == seg.lo { (end, end + t) } else { (end - t, end) };
                let touches_another = self.profiles.iter().enumerate().any(|(j, q)| j != attached_to && q.cuboid.touches(&slab, TOLERANCE));
                if touches_another {
                    return Err(format!("a {role:?} profile ends against two profiles"));
                }
                slabs.push(slab);
                let (mesh, cells) = self.connector_cells(&profile, end, end == seg.lo);
                let shape = if axis == 2 { ConnectorShape::O } else { ConnectorShape::U };
                connectors.push(Connector { shape, holds: index, attached_to, cells, mesh, fixed });
            }
        }
        let new_boxes = std::iter::once(&profile.cuboid).chain(connectors.iter().flat_map(|c| &c.cells));
        let existing: Vec<&Cuboid> = self.profiles.iter().map(|p| &p.cuboid).chain(self.connectors.iter().flat_map(|c| &c.cells)).collect();
        for b in new_boxes {
            if existing.iter().any(|e| e.overlaps(b, TOLERANCE)) {
                return Err(format!("a {role:?} profile overlaps an existing part"));
            }
        }
        self.profiles.push(profile);
        self.connectors.extend(connectors);
        self.end_slabs.extend(slabs);
        Ok(index)
    }

    /// The cells of the connector at end `end` of the free stretch of `profile` (`at_lo`: its
    /// lower end), i.e. on the face of the profile it meets.
    ///
    /// U (horizontal profiles): an end plate between the profile's end and the face it meets, a
    /// floor plate under the profile reaching `connector_length` from the face, and two side
    /// walls that start two wall thicknesses from the face, so two cradles meeting a post from
    /// perpendicular sides never claim the same corner.
    /// O (vertical profiles): a ring of walls around the profile, `connector_length` high.
    fn connector_cells(&self, profile: &Profile, end: f64, at_lo: bool) -> (Mesh, Vec<Cuboid>) {
        let (d, t, c) = (self.p.profile_size, self.p.connector_thickness, self.p.connector_length);
        let a = profile.axis;
        let centre = profile.centre();
        let around = |v: f64| vec![v - d / 2.0 - t, v - d / 2.0, v + d / 2.0, v + d / 2.0 + t];
        let mut lines: [Vec<f64>; 3] = Default::default();
        let mut cells = Vec::new();
        if a == 2 {
            lines = [around(centre[0]), around(centre[1]), if at_lo { vec![end, end + c] } else { vec![end - c, end] }];
            for i in 0..3 {
                for j in 0..3 {
                    if (i, j) != (1, 1) {
                        cells.push([i, j, 0]);
                    }
                }
            }
        } else {
            let b = 1 - a;
            lines[a] = if at_lo { vec![end, end + t, end + 2.0 * t, end + c] } else { vec![end - c, end - 2.0 * t, end - t, end] };
            lines[b] = around(centre[b]);
            lines[2] = vec![centre[2] - d / 2.0 - t, centre[2] - d / 2.0, centre[2] + d / 2.0];
            let (near, far) = if at_lo { (0, 2) } else { (2, 0) };
            let mut cell = |ia: i32, ib: i32, iz: i32| {
                let mut c = [0; 3];
                (c[a], c[b], c[2]) = (ia, ib, iz);
                cells.push(c);
            };
            cell(near, 1, 1);
            for ia in 0..3 {
                cell(ia, 1, 0);
            }
            for ib in [0, 2] {
                for iz in [0, 1] {
                    cell(far, ib, iz);
                }
            }
        }
        grid_union([&lines[0], &lines[1], &lines[2]], &cells)
    }
}
