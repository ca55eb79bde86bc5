//! Portal culling on the host: a generated house of rooms and doors, its
//! cells and portals for [`microraster::portal`], and the measurement of
//! `microraster cull --portals`.
//!
//! Design note: [`House::generate`] lays out `n x n` square rooms with
//! walls [`WALL`] thick, joined by doors along a random spanning tree (every
//! room reachable) plus a few extra doors, and furnishes every room with
//! two crates and a ball. Each room is one cell; each door two portals, one
//! from each side, the opening's rectangle on that side's wall face. The
//! meshes keep the core's promise ([`microraster::portal`]): each room's
//! shell (floor, ceiling, the inner faces of its walls) is closed but for
//! its doors, with every wall split at the doors' sides and at the doors'
//! height so that no vertex lies inside another triangle's edge
//! (T-junctions would open cracks), and every door's tunnel (jambs, lintel,
//! threshold) is drawn by both of its rooms, in one colour, so that either
//! draws the same pixels. The walls' thickness keeps another room's
//! surfaces at least a few depth steps behind a wall, where a 16-bit depth
//! buffer still orders them. [`House::scene`] draws the rooms the walk
//! reaches from the eye's room, or all of them.

use crate::scene::{self, Object, ObjectColors, Scene};
use microraster::occlusion::Aabb;
use microraster::pixelcolor::{Rgb888, RgbColor};
use microraster::portal::{Cell, PixelRect, Portal, PortalCount, PortalGraph};
use microraster::{BoundingSphere, Config, Mat4, Vec3};

/// Distance between neighbouring rooms' centres (and walls' centres).
pub const ROOM: f32 = 4.0;
/// Wall thickness.
pub const WALL: f32 = 0.25;
/// Ceiling height.
pub const HEIGHT: f32 = 2.6;
/// Door width.
pub const DOOR_WIDTH: f32 = 1.0;
/// Door height.
pub const DOOR_HEIGHT: f32 = 2.0;
/// The eye's height above the floor.
pub const EYE_HEIGHT: f32 = 1.6;
/// Rooms a side of the `house` scene.
pub const HOUSE_ROOMS: usize = 8;
/// The near plane (with the cameras at least [`CAMERA_MARGIN`] from every
/// wall, the near plane's rectangle stays inside the eye's room).
pub const NEAR: f32 = 0.3;
/// How far cameras keep from the walls.
pub const CAMERA_MARGIN: f32 = 0.7;

/// The house: rooms, doors, meshes, cells and portals.
#[derive(Clone, Debug)]
pub struct House {
    n: usize,
    /// Objects in drawing order, each with its room.
    objects: Vec<(usize, Object)>,
    cells: Vec<Cell>,
    portals: Vec<Portal>,
}

/// What [`House::scene`] skipped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PortalReport {
    /// The walk's counts (`None`: portals off, or the eye in no room).
    pub count: Option<PortalCount>,
    /// Objects skipped.
    pub objects: u64,
    /// Their triangles ([`microraster::Stats::culled_portal`]).
    pub triangles: u64,
}

/// A small deterministic generator (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / 16_777_216.0
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Triangles and flat colours under construction.
#[derive(Default)]
struct MeshBuilder {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    colors: Vec<Rgb888>,
}

impl MeshBuilder {
    fn vertex(&mut self, p: Vec3) -> u32 {
        self.positions.push(p);
        (self.positions.len() - 1) as u32
    }

    /// A triangle facing `normal` (wound counter-clockwise seen from that
    /// side), shaded by a fixed light.
    fn triangle(&mut self, p: [Vec3; 3], normal: Vec3, color: [f32; 3]) {
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let p = if n.dot(normal) < 0.0 {
            [p[0], p[2], p[1]]
        } else {
            p
        };
        let light = Vec3::new(0.3, 0.8, 0.5).normalize();
        let s = 0.45 + 0.55 * normal.normalize().dot(light).abs();
        let i = p.map(|q| self.vertex(q));
        self.indices.push(i);
        self.colors.push(Rgb888::new(
            (color[0] * s) as u8,
            (color[1] * s) as u8,
            (color[2] * s) as u8,
        ));
    }

    fn quad(&mut self, p: [Vec3; 4], normal: Vec3, color: [f32; 3]) {
        self.triangle([p[0], p[1], p[2]], normal, color);
        self.triangle([p[0], p[2], p[3]], normal, color);
    }

    fn object(self) -> Object {
        Object {
            bounds: BoundingSphere::from_points(&self.positions),
            aabb: Aabb::from_points(&self.positions),
            positions: self.positions,
            indices: self.indices,
            colors: ObjectColors::PerTriangle(self.colors),
            mvp: Mat4::IDENTITY,
            clusters: None,
            normal_classes: None,
            parts: None,
            detail_fill: None,
        }
    }
}

/// A door in the wall between room `(i, j)` and its neighbour in `+x`
/// (`along_x == false`: the wall at `x = (i + 1) ROOM`) or in `+z`; its
/// opening spans `lo..lo + DOOR_WIDTH` along the wall.
#[derive(Clone, Copy, Debug)]
struct Door {
    i: usize,
    j: usize,
    toward_z: bool,
    lo: f32,
}

impl House {
    /// `n x n` rooms from `seed`.
    pub fn generate(n: usize, seed: u64) -> House {
        let n = n.clamp(1, 64);
        let mut rng = Rng(seed);
        // A random spanning tree (depth-first from room 0), then extra
        // doors with probability 1/5.
        let mut doors: Vec<Door> = Vec::new();
        let mut seen = vec![false; n * n];
        let mut stack = vec![0usize];
        seen[0] = true;
        let door = |rng: &mut Rng, a: usize, b: usize| {
            let (a, b) = (a.min(b), a.max(b));
            let toward_z = b - a == 1;
            let span = ROOM - WALL - DOOR_WIDTH - 0.6;
            Door {
                i: a / n,
                j: a % n,
                toward_z,
                lo: 0.3 + rng.unit() * span,
            }
        };
        let neighbours = |r: usize| {
            let (i, j) = (r / n, r % n);
            let mut v = Vec::new();
            if i > 0 {
                v.push(r - n);
            }
            if i + 1 < n {
                v.push(r + n);
            }
            if j > 0 {
                v.push(r - 1);
            }
            if j + 1 < n {
                v.push(r + 1);
            }
            v
        };
        let mut joined = std::collections::BTreeSet::new();
        while let Some(&r) = stack.last() {
            let open: Vec<usize> = neighbours(r).into_iter().filter(|&m| !seen[m]).collect();
            if open.is_empty() {
                stack.pop();
                continue;
            }
            let m = open[rng.below(open.len())];
            seen[m] = true;
            joined.insert((r.min(m), r.max(m)));
            doors.push(door(&mut rng, r, m));
            stack.push(m);
        }
        for r in 0..n * n {
            for m in neighbours(r) {
                if m > r && !joined.contains(&(r, m)) && rng.below(5) == 0 {
                    doors.push(door(&mut rng, r, m));
                }
            }
        }
        let mut objects = Vec::new();
        let mut out: Vec<Vec<Portal>> = vec![Vec::new(); n * n];
        for (room, out) in out.iter_mut().enumerate() {
            let mine: Vec<&Door> = doors
                .iter()
                .filter(|d| {
                    let a = d.i * n + d.j;
                    let b = if d.toward_z { a + 1 } else { a + n };
                    a == room || b == room
                })
                .collect();
            objects.push((room, shell(n, room, &mine)));
            for d in &mine {
                let a = d.i * n + d.j;
                let b = if d.toward_z { a + 1 } else { a + n };
                // This side's face of the wall: half a wall before its
                // centre line for the lower room, after it for the other.
                let (other, side) = if a == room {
                    (b, -0.5 * WALL)
                } else {
                    (a, 0.5 * WALL)
                };
                let bounds = if d.toward_z {
                    let z = (d.j as f32 + 1.0) * ROOM + side;
                    let x0 = d.i as f32 * ROOM + d.lo;
                    Aabb::new(
                        Vec3::new(x0, 0.0, z),
                        Vec3::new(x0 + DOOR_WIDTH, DOOR_HEIGHT, z),
                    )
                } else {
                    let x = (d.i as f32 + 1.0) * ROOM + side;
                    let z0 = d.j as f32 * ROOM + d.lo;
                    Aabb::new(
                        Vec3::new(x, 0.0, z0),
                        Vec3::new(x, DOOR_HEIGHT, z0 + DOOR_WIDTH),
                    )
                };
                out.push(Portal {
                    to: other as u16,
                    bounds,
                });
            }
            let (i, j) = (room / n, room % n);
            let (cx, cz) = ((i as f32 + 0.5) * ROOM, (j as f32 + 0.5) * ROOM);
            for k in 0..2 {
                let (w, h, d) = (
                    0.4 + rng.unit() * 0.5,
                    0.3 + rng.unit() * 0.7,
                    0.4 + rng.unit() * 0.5,
                );
                let x = cx + (rng.unit() - 0.5) * (ROOM - 2.0 * CAMERA_MARGIN - 1.4);
                let z = cz + (rng.unit() - 0.5) * (ROOM - 2.0 * CAMERA_MARGIN - 1.4);
                let color = [
                    120.0 + 120.0 * rng.unit(),
                    80.0 + 100.0 * rng.unit(),
                    60.0 + 60.0 * k as f32,
                ];
                objects.push((room, crate_box(x, z, w, h, d, color)));
            }
            let r = 0.25 + 0.15 * rng.unit();
            let x = cx + (rng.unit() - 0.5) * (ROOM - 2.0 * CAMERA_MARGIN - 1.0);
            let z = cz + (rng.unit() - 0.5) * (ROOM - 2.0 * CAMERA_MARGIN - 1.0);
            objects.push((room, ball(Vec3::new(x, r, z), r, &mut rng)));
        }
        let mut cells = Vec::with_capacity(n * n);
        let mut portals = Vec::new();
        for p in out {
            cells.push(Cell {
                first: portals.len() as u16,
                count: p.len() as u16,
            });
            portals.extend(p);
        }
        House {
            n,
            objects,
            cells,
            portals,
        }
    }

    /// Rooms a side.
    pub fn rooms(&self) -> usize {
        self.n
    }

    /// The cells and portals, checked.
    pub fn graph(&self) -> Result<PortalGraph<'_>, String> {
        PortalGraph::new(&self.cells, &self.portals).map_err(|e| e.to_string())
    }

    /// The room whose floor (walls excluded) holds `eye`, if any.
    pub fn room_of(&self, eye: [f32; 3]) -> Option<usize> {
        let cell = |v: f32| {
            let k = (v / ROOM).floor();
            let f = v - k * ROOM;
            (k >= 0.0 && (k as usize) < self.n && f > 0.5 * WALL && f < ROOM - 0.5 * WALL)
                .then_some(k as usize)
        };
        if !(eye[1] > 0.0 && eye[1] < HEIGHT) {
            return None;
        }
        Some(cell(eye[0])? * self.n + cell(eye[2])?)
    }

    /// Triangles in all rooms.
    pub fn triangles(&self) -> usize {
        self.objects.iter().map(|(_, o)| o.indices.len()).sum()
    }

    /// The house from `eye` towards `target` (`fov` degrees, `aspect`) in a
    /// frame of `width x height`: with `portals`, only the objects of the
    /// rooms the portal walk reaches from the eye's room (all of them if
    /// the eye is in no room).
    #[allow(clippy::too_many_arguments)]
    pub fn scene(
        &self,
        eye: [f32; 3],
        target: [f32; 3],
        fov: f32,
        width: u32,
        height: u32,
        inv_w: bool,
        portals: bool,
    ) -> Result<(Scene, PortalReport), String> {
        let view_proj = self.view_proj(eye, target, fov, width, height, inv_w)?;
        let mut report = PortalReport::default();
        let mut reached = vec![true; self.cells.len()];
        if let (true, Some(start)) = (portals, self.room_of(eye)) {
            let config = Config::new(width, height);
            let mut rects = vec![PixelRect::EMPTY; self.cells.len()];
            let count = self
                .graph()?
                .visible(&view_proj, &config, start, &mut rects)
                .map_err(|e| e.to_string())?;
            report.count = Some(count);
            for (r, rect) in reached.iter_mut().zip(&rects) {
                *r = !rect.is_empty();
            }
        }
        let mut objects = Vec::new();
        for (room, o) in &self.objects {
            if reached[*room] {
                objects.push(Object {
                    mvp: view_proj,
                    ..o.clone()
                });
            } else {
                report.objects += 1;
                report.triangles += o.indices.len() as u64;
            }
        }
        Ok((
            Scene {
                objects,
                clip_tris: Vec::new(),
            },
            report,
        ))
    }
}

/// Rooms a side of the house the firmware draws (`bake-house`): the
/// `house` scene's.
pub const FIRMWARE_ROOMS: usize = HOUSE_ROOMS;
/// The camera of record of the firmware's house ([`house_camera`]`(k, 8)`):
/// one whose walk reaches five of the 64 rooms (the 64 cameras of `cull
/// --portals` reach 5.4 on average).
pub const FIRMWARE_CAMERA: usize = 2;
/// Cameras of the firmware's sweep: the first of [`house_camera`]'s.
pub const FIRMWARE_SWEEP: usize = 64;

impl House {
    /// World to clip for `eye` towards `target`, as [`House::scene`] draws.
    pub fn view_proj(
        &self,
        eye: [f32; 3],
        target: [f32; 3],
        fov: f32,
        width: u32,
        height: u32,
        inv_w: bool,
    ) -> Result<Mat4, String> {
        let aspect = width as f32 / height as f32;
        let far = self.n as f32 * ROOM * 1.5 + 2.0;
        let proj = scene::projection(inv_w, microraster::math::radians(fov), aspect, NEAR, far);
        Ok(proj * scene::look_at(eye, target)?)
    }

    /// The objects with their rooms, in drawing order.
    pub fn objects(&self) -> impl Iterator<Item = (usize, &Object)> {
        self.objects.iter().map(|(r, o)| (*r, o))
    }

    /// Rust source (`include!`, `no_std`, plain arrays in flash) of the
    /// house seen from [`house_camera`]`(camera, n)` in a frame of
    /// `width x height` (60° vertical field of view): the world-to-clip
    /// matrix and the eye's cell, the same for [`FIRMWARE_SWEEP`] cameras
    /// from 0, every object's vertices (a flat object's equal positions
    /// shared, which draws the same pixels), triangles, colours (per
    /// triangle, or per vertex for the balls), room and bounding sphere,
    /// and the cells and portals of [`PortalGraph`].
    pub fn bake_source(&self, camera: usize, width: u32, height: u32) -> Result<String, String> {
        use crate::bake::f32_literal as f;
        use std::fmt::Write;
        // Camera k: its eye, target, eye's cell and matrix.
        let camera_k = |k: usize| -> Result<_, String> {
            let (eye, target) = house_camera(k, self.n);
            let start = self
                .room_of(eye)
                .ok_or_else(|| format!("camera {k} is in no room"))?;
            let vp = self.view_proj(eye, target, 60.0, width, height, false)?;
            Ok((eye, target, start, vp))
        };
        let (eye, target, start, vp) = camera_k(camera)?;
        let config = Config::new(width, height);
        let mut rects = vec![PixelRect::EMPTY; self.cells.len()];
        let count = self
            .graph()?
            .visible(&vp, &config, start, &mut rects)
            .map_err(|e| e.to_string())?;
        let v3 = |p: Vec3| format!("Vec3::new({}, {}, {})", f(p.x), f(p.y), f(p.z));
        let (mut positions, mut indices, mut colors, mut objects) =
            (String::new(), String::new(), String::new(), String::new());
        let (mut nv, mut nt, mut nc) = (0usize, 0usize, 0usize);
        for (room, o) in &self.objects {
            // Flat objects share equal positions (the same pixels: a
            // vertex's position alone decides its clip coordinates); the
            // balls' colours are per vertex, so their vertices stay.
            let (c, per_vertex) = match &o.colors {
                ObjectColors::PerTriangle(c) => (c, false),
                ObjectColors::PerVertex(c) => (c, true),
            };
            let mut seen = std::collections::HashMap::new();
            let mut local = Vec::new();
            let remap: Vec<u32> = o
                .positions
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    if per_vertex {
                        local.push(*p);
                        return i as u32;
                    }
                    let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
                    *seen.entry(key).or_insert_with(|| {
                        local.push(*p);
                        (local.len() - 1) as u32
                    })
                })
                .collect();
            let (v0, t0, c0) = (nv, nt, nc);
            for p in &local {
                let _ = writeln!(positions, "    {},", v3(*p));
            }
            for t in &o.indices {
                let t = t.map(|i| remap[i as usize]);
                let _ = writeln!(indices, "    [{}, {}, {}],", t[0], t[1], t[2]);
            }
            for col in c {
                let _ = writeln!(
                    colors,
                    "    Rgb888::new({}, {}, {}),",
                    col.r(),
                    col.g(),
                    col.b()
                );
            }
            nv += local.len();
            nt += o.indices.len();
            nc += c.len();
            let b = o.bounds.ok_or("a house object without a bounding sphere")?;
            let _ = writeln!(
                objects,
                "    HouseObject {{ room: {room}, positions: [{v0}, {nv}], triangles: [{t0}, {nt}], colors: [{c0}, {nc}], per_vertex: {per_vertex}, sphere: BoundingSphere {{ center: {}, radius: {} }} }},",
                v3(b.center),
                f(b.radius)
            );
        }
        let mut cells = String::new();
        for c in &self.cells {
            let _ = writeln!(
                cells,
                "    Cell {{ first: {}, count: {} }},",
                c.first, c.count
            );
        }
        let mut portals = String::new();
        for p in &self.portals {
            let _ = writeln!(
                portals,
                "    Portal {{ to: {}, bounds: Aabb::new({}, {}) }},",
                p.to,
                v3(p.bounds.min),
                v3(p.bounds.max)
            );
        }
        let mat = |m: &Mat4| {
            let cols = m
                .cols
                .iter()
                .map(|c| format!("[{}]", c.map(f).join(", ")))
                .collect::<Vec<_>>()
                .join(", ");
            format!("Mat4 {{ cols: [{cols}] }}")
        };
        let cols = mat(&vp);
        let mut sweep = String::new();
        for k in 0..FIRMWARE_SWEEP {
            let (_, _, start, vp) = camera_k(k)?;
            let _ = writeln!(
                sweep,
                "    HouseCamera {{ view_proj: {}, start: {start} }},",
                mat(&vp)
            );
        }
        let n = self.n;
        let reached = rects.iter().filter(|r| !r.is_empty()).count();
        let (no, ncells, np) = (self.objects.len(), self.cells.len(), self.portals.len());
        let last = FIRMWARE_SWEEP - 1;
        Ok(format!(
            "// Generated by `microraster bake-house --rooms {n} --camera {camera}`: do not edit.\n\
             // A house of {n}x{n} rooms (`microraster_host::portal::House`, seed 1): {nt} triangles,\n\
             // {nv} vertices, {no} objects, {ncells} cells, {np} portals; camera {camera}, whose portal\n\
             // walk reaches {reached} of the {ncells} rooms ({} portal projections).\n\
             \n\
             use microraster::occlusion::Aabb;\n\
             use microraster::pixelcolor::Rgb888;\n\
             use microraster::portal::{{Cell, Portal}};\n\
             use microraster::{{BoundingSphere, Mat4, Vec3}};\n\
             \n\
             /// Rooms a side.\n\
             pub const ROOMS: usize = {n};\n\
             /// The frame the matrix is for.\n\
             pub const WIDTH: u32 = {width};\n\
             /// The frame the matrix is for.\n\
             pub const HEIGHT: u32 = {height};\n\
             /// The camera: eye and target in world space (60° vertical field of view).\n\
             pub const EYE: [f32; 3] = [{}, {}, {}];\n\
             /// The camera's target.\n\
             pub const TARGET: [f32; 3] = [{}, {}, {}];\n\
             /// The cell (room) the eye is in.\n\
             pub const START: usize = {start};\n\
             /// World to clip (the host's, bit for bit).\n\
             pub const VIEW_PROJ: Mat4 = {cols};\n\
             \n\
             /// A camera: world to clip and the eye's cell.\n\
             #[derive(Clone, Copy, Debug)]\n\
             pub struct HouseCamera {{\n    \
                 pub view_proj: Mat4,\n    \
                 pub start: usize,\n\
             }}\n\
             \n\
             /// The sweep: cameras 0 to {last} of `cull --portals` in this house.\n\
             pub static SWEEP: [HouseCamera; {FIRMWARE_SWEEP}] = [\n{sweep}];\n\
             \n\
             /// One object: its room, its ranges of `POSITIONS`, `INDICES` (which\n\
             /// count from its first vertex) and `COLORS` (one a vertex if\n\
             /// `per_vertex`, else one a triangle), its sphere.\n\
             #[derive(Clone, Copy, Debug)]\n\
             pub struct HouseObject {{\n    \
                 pub room: u16,\n    \
                 pub positions: [u32; 2],\n    \
                 pub triangles: [u32; 2],\n    \
                 pub colors: [u32; 2],\n    \
                 pub per_vertex: bool,\n    \
                 pub sphere: BoundingSphere,\n\
             }}\n\
             \n\
             /// Object space is world space.\n\
             pub static POSITIONS: [Vec3; {nv}] = [\n{positions}];\n\
             \n\
             /// Triangles, indices into their object's positions.\n\
             pub static INDICES: [[u32; 3]; {nt}] = [\n{indices}];\n\
             \n\
             /// Colours (lit once, when generated).\n\
             pub static COLORS: [Rgb888; {nc}] = [\n{colors}];\n\
             \n\
             /// The objects in drawing order.\n\
             pub static OBJECTS: [HouseObject; {no}] = [\n{objects}];\n\
             \n\
             /// A cell a room (`room = i * ROOMS + j`).\n\
             pub static CELLS: [Cell; {ncells}] = [\n{cells}];\n\
             \n\
             /// Each door's two portals, one out of each room.\n\
             pub static PORTALS: [Portal; {np}] = [\n{portals}];\n",
            count.projected,
            f(eye[0]),
            f(eye[1]),
            f(eye[2]),
            f(target[0]),
            f(target[1]),
            f(target[2]),
        ))
    }
}

/// The `house` scene: a [`HOUSE_ROOMS`]² house from camera 0 of
/// [`house_camera`] (or as `view` says), 60° vertical field of view; with
/// `view.portals`, the rooms the walk reaches only, and what it skipped.
pub fn house_scene(view: &scene::View) -> Result<(Scene, PortalReport), String> {
    let house = House::generate(HOUSE_ROOMS, 1);
    let (e, t) = house_camera(0, HOUSE_ROOMS);
    house.scene(
        view.eye.unwrap_or(e),
        view.target.unwrap_or(t),
        view.fov.unwrap_or(60.0),
        view.width,
        view.height,
        view.inv_w,
        view.portals,
    )
}

/// Camera `k` in an `n x n` house: in a room picked by `k`, at
/// least [`CAMERA_MARGIN`] from its walls, at eye height, looking level in
/// a direction picked by `k`, slightly down. Eye and target.
pub fn house_camera(k: usize, n: usize) -> ([f32; 3], [f32; 3]) {
    let mut rng = Rng(0x5eed_0000 + k as u64);
    let room = rng.below(n * n);
    let (i, j) = (room / n, room % n);
    let inner = ROOM - WALL - 2.0 * CAMERA_MARGIN;
    let x = i as f32 * ROOM + 0.5 * WALL + CAMERA_MARGIN + rng.unit() * inner;
    let z = j as f32 * ROOM + 0.5 * WALL + CAMERA_MARGIN + rng.unit() * inner;
    let yaw = rng.unit() * std::f32::consts::TAU;
    let eye = [x, EYE_HEIGHT, z];
    (eye, [x + yaw.cos(), EYE_HEIGHT - 0.15, z + yaw.sin()])
}

/// Room `room`'s shell: floor, ceiling and the inner faces of its four
/// walls with holes for `doors`, and the tunnels of those doors.
fn shell(n: usize, room: usize, doors: &[&Door]) -> Object {
    let (i, j) = (room / n, room % n);
    let x0 = i as f32 * ROOM + 0.5 * WALL;
    let x1 = (i + 1) as f32 * ROOM - 0.5 * WALL;
    let z0 = j as f32 * ROOM + 0.5 * WALL;
    let z1 = (j + 1) as f32 * ROOM - 0.5 * WALL;
    let tint = [
        170.0 + 60.0 * ((room * 7) % 5) as f32 / 4.0,
        160.0 + 60.0 * ((room * 3) % 4) as f32 / 3.0,
        150.0 + 70.0 * ((room * 5) % 3) as f32 / 2.0,
    ];
    // Each wall: its door openings as offsets from its start (the room's
    // local coordinate along it).
    let openings = |side: usize| -> Vec<f32> {
        let mut v: Vec<f32> = doors
            .iter()
            .filter_map(|d| {
                let a = d.i * n + d.j;
                let on = match side {
                    // -x wall (x = x0): doors toward +x from room - n.
                    0 => !d.toward_z && a + n == room,
                    1 => !d.toward_z && a == room,
                    2 => d.toward_z && a + 1 == room,
                    _ => d.toward_z && a == room,
                };
                // `lo` counts from the rooms' common grid line; the wall
                // starts half a wall later.
                on.then_some(d.lo - 0.5 * WALL)
            })
            .collect();
        v.sort_by(f32::total_cmp);
        v
    };
    let mut m = MeshBuilder::default();
    // Walls: (start, direction along, length, inward normal).
    let walls = [
        (
            Vec3::new(x0, 0.0, z0),
            Vec3::new(0.0, 0.0, 1.0),
            z1 - z0,
            Vec3::new(1.0, 0.0, 0.0),
        ),
        (
            Vec3::new(x1, 0.0, z0),
            Vec3::new(0.0, 0.0, 1.0),
            z1 - z0,
            Vec3::new(-1.0, 0.0, 0.0),
        ),
        (
            Vec3::new(x0, 0.0, z0),
            Vec3::new(1.0, 0.0, 0.0),
            x1 - x0,
            Vec3::new(0.0, 0.0, 1.0),
        ),
        (
            Vec3::new(x0, 0.0, z1),
            Vec3::new(1.0, 0.0, 0.0),
            x1 - x0,
            Vec3::new(0.0, 0.0, -1.0),
        ),
    ];
    let up = Vec3::new(0.0, 1.0, 0.0);
    let at = |o: Vec3, u: Vec3, s: f32, h: f32| o + u * s + up * h;
    // Floor and ceiling boundary points, counter-clockwise from above.
    let mut ring: Vec<Vec3> = Vec::new();
    let mut cuts_of = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    for (side, &(o, u, len, inward)) in walls.iter().enumerate() {
        let mut cuts = vec![0.0];
        let doors_here = openings(side);
        for &lo in &doors_here {
            cuts.push(lo);
            cuts.push(lo + DOOR_WIDTH);
        }
        cuts.push(len);
        for k in 0..cuts.len() - 1 {
            let (a, b) = (cuts[k], cuts[k + 1]);
            let is_door = doors_here.contains(&a);
            if !is_door {
                m.quad(
                    [
                        at(o, u, a, 0.0),
                        at(o, u, b, 0.0),
                        at(o, u, b, DOOR_HEIGHT),
                        at(o, u, a, DOOR_HEIGHT),
                    ],
                    inward,
                    tint,
                );
            }
            m.quad(
                [
                    at(o, u, a, DOOR_HEIGHT),
                    at(o, u, b, DOOR_HEIGHT),
                    at(o, u, b, HEIGHT),
                    at(o, u, a, HEIGHT),
                ],
                inward,
                tint,
            );
        }
        // The tunnel of each door behind this wall, drawn by both rooms in
        // the door's own colour: through the wall to the other face.
        for &lo in &doors_here {
            let back = inward * -WALL;
            let (a, b) = (lo, lo + DOOR_WIDTH);
            let c = [200.0, 170.0, 120.0];
            let p = |s: f32, h: f32, d: bool| {
                at(o, u, s, h) + if d { back } else { Vec3::new(0.0, 0.0, 0.0) }
            };
            // Jambs face each other, the lintel down, the threshold up.
            m.quad(
                [
                    p(a, 0.0, false),
                    p(a, 0.0, true),
                    p(a, DOOR_HEIGHT, true),
                    p(a, DOOR_HEIGHT, false),
                ],
                u,
                c,
            );
            m.quad(
                [
                    p(b, 0.0, false),
                    p(b, 0.0, true),
                    p(b, DOOR_HEIGHT, true),
                    p(b, DOOR_HEIGHT, false),
                ],
                u * -1.0,
                c,
            );
            m.quad(
                [
                    p(a, DOOR_HEIGHT, false),
                    p(b, DOOR_HEIGHT, false),
                    p(b, DOOR_HEIGHT, true),
                    p(a, DOOR_HEIGHT, true),
                ],
                up * -1.0,
                c,
            );
            m.quad(
                [
                    p(a, 0.0, false),
                    p(b, 0.0, false),
                    p(b, 0.0, true),
                    p(a, 0.0, true),
                ],
                up,
                [150.0, 120.0, 90.0],
            );
        }
        cuts_of[side] = cuts;
    }
    // The ring: -z wall (side 2) forward, +x wall (1) forward, +z wall (3)
    // backward, -x wall (0) backward; each wall's last cut is the next's
    // first, so it is skipped.
    for (side, forward) in [(2, true), (1, true), (3, false), (0, false)] {
        let (o, u, _, _) = walls[side];
        let cuts = &cuts_of[side];
        let pts: Vec<f32> = if forward {
            cuts[..cuts.len() - 1].to_vec()
        } else {
            cuts[1..].iter().rev().copied().collect()
        };
        for s in pts {
            ring.push(at(o, u, s, 0.0));
        }
    }
    let centre = Vec3::new(0.5 * (x0 + x1), 0.0, 0.5 * (z0 + z1));
    for k in 0..ring.len() {
        let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
        m.triangle([centre, a, b], up, [110.0, 100.0, 95.0]);
        let h = up * HEIGHT;
        m.triangle([centre + h, a + h, b + h], up * -1.0, [235.0, 235.0, 230.0]);
    }
    m.object()
}

/// A crate of `w x h x d` standing on the floor at `(x, z)`.
fn crate_box(x: f32, z: f32, w: f32, h: f32, d: f32, color: [f32; 3]) -> Object {
    let mut m = MeshBuilder::default();
    let (a, b) = (
        Vec3::new(x - 0.5 * w, 0.0, z - 0.5 * d),
        Vec3::new(x + 0.5 * w, h, z + 0.5 * d),
    );
    let c = |i: usize, j: usize, k: usize| Vec3::new([a.x, b.x][i], [a.y, b.y][j], [a.z, b.z][k]);
    for axis in 0..3 {
        for side in 0..2 {
            let mut n = [0.0f32; 3];
            n[axis] = if side == 0 { -1.0 } else { 1.0 };
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let corner = |su: usize, sv: usize| {
                let mut idx = [0usize; 3];
                idx[axis] = side;
                idx[u] = su;
                idx[v] = sv;
                c(idx[0], idx[1], idx[2])
            };
            m.quad(
                [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)],
                Vec3::from_array(n),
                color,
            );
        }
    }
    m.object()
}

/// A ball of radius `r` at `c`, 16 x 24 facets.
fn ball(c: Vec3, r: f32, rng: &mut Rng) -> Object {
    let (positions, indices) = crate::bench_scenes::uv_sphere(16, 24, r);
    let tint = [
        90.0 + 160.0 * rng.unit(),
        90.0 + 160.0 * rng.unit(),
        90.0 + 160.0 * rng.unit(),
    ];
    let light = Vec3::new(0.3, 0.8, 0.5).normalize();
    let colors = positions
        .iter()
        .map(|p| {
            let s = 0.3 + 0.7 * p.normalize().dot(light).max(0.0);
            Rgb888::new(
                (tint[0] * s) as u8,
                (tint[1] * s) as u8,
                (tint[2] * s) as u8,
            )
        })
        .collect();
    let positions: Vec<Vec3> = positions.into_iter().map(|p| p + c).collect();
    Object {
        bounds: BoundingSphere::from_points(&positions),
        aabb: Aabb::from_points(&positions),
        positions,
        indices,
        colors: ObjectColors::PerVertex(colors),
        mvp: Mat4::IDENTITY,
        clusters: None,
        normal_classes: None,
        parts: None,
        detail_fill: None,
    }
}

/// The portal table's figures: the `house` from every camera, without and
/// with portal culling.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PortalRow {
    /// Rooms (cells) in the house.
    pub cells: u32,
    /// Rooms reached per frame, averaged over the cameras.
    pub reached: f64,
    /// Triangles in the house.
    pub triangles: u64,
    /// Triangles skipped with their rooms per frame (before submission).
    pub culled_portal: f64,
    /// Triangles set up per frame without and with portal culling.
    pub stored: [f64; 2],
    /// Frame time without and with, ms (walk and scene included): median
    /// over the rounds, then the range.
    pub frame_ms: [[f64; 3]; 2],
    /// The walk and building the scene of the rooms reached, µs per
    /// frame (median round).
    pub walk_us: f64,
    /// Whether every camera's image and depth were identical.
    pub identical: bool,
}

/// Measures portal culling on an `n x n` [`House`] from `cameras` cameras
/// ([`house_camera`]) at `size`, one thread, 16-row strips, `u16` depth,
/// interleaved A B A B `rounds` times (a round's time is its sum over the
/// cameras).
pub fn measure(
    n: usize,
    cameras: usize,
    size: (u32, u32),
    rounds: usize,
) -> Result<PortalRow, String> {
    use crate::render::{render, DepthKind, Occlusion, RenderOptions};
    let house = House::generate(n, 1);
    let (w, h) = size;
    let opts = RenderOptions {
        width: w,
        height: h,
        cull: microraster::CullMode::Back,
        detail: 0,
        depth: DepthKind::U16,
        subpixel: 8,
        threads: 1,
        strip_rows: 16.min(h).max(1),
        tile_width: 0,
        ids: false,
        mode: microraster::RasterMode::Clipping,
        inv_w: false,
        occlusion: Occlusion::Off,
    };
    let rounds = rounds.max(1);
    let mut totals = vec![[0.0f64; 3]; rounds];
    let (mut reached, mut culled, mut stored) = (0.0, 0.0, [0.0f64; 2]);
    let mut identical = true;
    for k in 0..cameras {
        let (eye, target) = house_camera(k, house.rooms());
        let mut images = [None, None];
        for total in totals.iter_mut() {
            for (m, portals) in [false, true].into_iter().enumerate() {
                let t = std::time::Instant::now();
                let (scene, report) = house.scene(eye, target, 60.0, w, h, false, portals)?;
                let walked = t.elapsed().as_secs_f64() * 1e6;
                let img = render(&scene, &opts)?;
                total[m] += t.elapsed().as_secs_f64() * 1e3;
                if portals {
                    total[2] += walked;
                }
                images[m] = Some((img, report));
            }
        }
        if let [Some((a, _)), Some((b, r))] = &images {
            identical &= a.rgb == b.rgb && a.depth == b.depth;
            reached += r
                .count
                .map_or(house.cells.len() as f64, |c| c.reached as f64);
            culled += r.triangles as f64;
            stored[0] += a.stats.stored as f64;
            stored[1] += b.stats.stored as f64;
        }
    }
    let c = cameras.max(1) as f64;
    let spread = |m: usize| {
        let mut v: Vec<f64> = totals.iter().map(|t| t[m] / c).collect();
        v.sort_by(f64::total_cmp);
        [v[v.len() / 2], v[0], v[v.len() - 1]]
    };
    Ok(PortalRow {
        cells: house.cells.len() as u32,
        reached: reached / c,
        triangles: house.triangles() as u64,
        culled_portal: culled / c,
        stored: [stored[0] / c, stored[1] / c],
        frame_ms: [spread(0), spread(1)],
        walk_us: spread(2)[0],
        identical,
    })
}

/// The portal table as Markdown.
pub fn markdown(r: &PortalRow, n: usize, cameras: usize, size: (u32, u32)) -> String {
    let mut t = format!(
        "### house: {n}x{n} rooms, {cameras} cameras in the rooms, {}x{}, 1 thread, u16 depth\n\n",
        size.0, size.1
    );
    t += "| rooms | reached / frame | rooms skipped | triangles | skipped (portal) | set up, all rooms | set up, portals | frame ms, all rooms | frame ms, portals | speed-up | walk + scene µs | identical |\n";
    t += "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|:---:|\n";
    let ms = |m: [f64; 3]| format!("{:.2} ({:.2}-{:.2})", m[0], m[1], m[2]);
    t += &format!(
        "| {} | {:.2} | {:.1} % | {} | {:.1} % | {:.0} | {:.0} | {} | {} | {:.2}x | {:.1} | {} |\n",
        r.cells,
        r.reached,
        100.0 * (1.0 - r.reached / r.cells.max(1) as f64),
        r.triangles,
        100.0 * r.culled_portal / r.triangles.max(1) as f64,
        r.stored[0],
        r.stored[1],
        ms(r.frame_ms[0]),
        ms(r.frame_ms[1]),
        r.frame_ms[0][0] / r.frame_ms[1][0],
        r.walk_us,
        if r.identical { "yes" } else { "NO" }
    );
    t
}

/// `microraster bake-house`: writes `house.rs` into `args.out` (nothing
/// if the bake fails) and prints what it holds.
pub fn bake_run(args: &crate::cli::BakeHouseArgs) -> Result<(), String> {
    // The firmware keeps 12 bytes a room on its stack while it walks (the
    // rectangles, then the strips' bits): at 8x8 that leaves 684 B of the
    // 24 KB, and 8x8 is the `house` scene's size.
    if !(1..=8).contains(&args.rooms) {
        return Err(format!("--rooms must be 1 to 8, got {}", args.rooms));
    }
    let house = House::generate(args.rooms, 1);
    let (w, h) = args.size;
    let src = house.bake_source(args.camera, w, h)?;
    std::fs::create_dir_all(&args.out).map_err(|e| {
        format!(
            "{}: cannot create the output folder: {e}",
            args.out.display()
        )
    })?;
    let path = args.out.join("house.rs");
    crate::output::write_all(&[crate::output::Output {
        option: "--out",
        path: &path,
        payload: crate::output::Payload::Raw(src.as_bytes()),
    }])?;
    println!("wrote {}", path.display());
    if let Some(line) = src.lines().nth(1) {
        println!("{}", line.trim_start_matches("// "));
    }
    Ok(())
}
