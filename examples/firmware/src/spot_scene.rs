//! The Spot frame, shared by the firmware (`--features spot-*`) and
//! `build.rs` (which compiles this file with `#[path]` and the same
//! features, and renders the same frame on the host).
//!
//! Spot (`assets/models/spot.obj`, baked into `baked/`) seen from a fixed
//! camera in front of its face, with the model matrix the identity, so
//! normals, the light and the view direction are all in object space. One
//! shading variant is chosen at build time, by feature; only that
//! variant's attribute source and fragment shader are instantiated, so an
//! unlit, untextured build links no lighting and no texture code:
//!
//! | feature | attributes (`N`) | fragment shader |
//! |---|---|---|
//! | `spot-flat` | `MeshColors::Uniform` (the material's grey) (3) | `VertexColor` |
//! | `spot-gouraud` | `MeshColors::PerVertex`: colours from the normals, `(n + 1) / 2` (3) | `VertexColor` |
//! | `spot-lit` | `LitColors` over the grey (3) | `VertexColor` |
//! | `spot-textured` | `ColorUv { Uniform(white) }` (5) | `Textured` |
//! | `spot-textured-lit` | `ColorUv { LitColors over white }` (5) | `Textured` |
//! | `spot-phong` | `ColorUvNormal { Uniform(white) }` (8) | `Phong` with the texture |

#[cfg(not(any(
    feature = "spot-flat",
    feature = "spot-gouraud",
    feature = "spot-lit",
    feature = "spot-textured",
    feature = "spot-textured-lit",
    feature = "spot-phong"
)))]
compile_error!(
    "feature `spot` needs a shading variant: spot-flat, spot-gouraud, spot-lit, \
     spot-textured, spot-textured-lit or spot-phong"
);

const _: () = assert!(
    cfg!(feature = "spot-flat") as u8
        + cfg!(feature = "spot-gouraud") as u8
        + cfg!(feature = "spot-lit") as u8
        + cfg!(feature = "spot-textured") as u8
        + cfg!(feature = "spot-textured-lit") as u8
        + cfg!(feature = "spot-phong") as u8
        <= 1,
    "pick one Spot shading variant"
);

use microraster::math::radians;
#[allow(unused_imports)]
use microraster::pixelcolor::{Rgb888, RgbColor};
#[allow(unused_imports)]
use microraster::shade::{
    ColorUv, ColorUvNormal, DirectionalLight, Lighting, LitColors, Material, Phong, Texture,
    Textured,
};
#[allow(unused_imports)]
use microraster::{Attributes, Error, FragmentShader, Mat4, Mesh, MeshColors, Vec3, VertexColor};

/// The camera: in front of Spot's face (Spot faces -z), a little above it.
pub const EYE: Vec3 = Vec3::new(0.0, 0.3, -2.6);
/// The point the camera looks at.
pub const TARGET: Vec3 = Vec3::new(0.0, 0.1, 0.2);

/// The feature's name, for the firmware's first line.
#[allow(dead_code)]
pub const VARIANT: &str = if cfg!(feature = "spot-flat") {
    "flat (uniform colour, unlit)"
} else if cfg!(feature = "spot-gouraud") {
    "Gouraud (colours from the normals, unlit)"
} else if cfg!(feature = "spot-lit") {
    "lit Gouraud (LitColors)"
} else if cfg!(feature = "spot-textured") {
    "textured (unlit)"
} else if cfg!(feature = "spot-textured-lit") {
    "textured, lit per vertex"
} else {
    "Phong, textured"
};

/// The baked model, as slices (in flash on the device); each variant reads
/// some of the fields.
#[allow(dead_code)]
pub struct Model<'a> {
    pub positions: &'a [Vec3],
    pub indices: &'a [[u32; 3]],
    pub normals: &'a [Vec3],
    pub uvs: &'a [[f32; 2]],
    /// Rgb565 words, row 0 first.
    pub texture: &'a [u16],
    pub texture_width: u32,
    pub texture_height: u32,
    /// The material's diffuse colour.
    pub diffuse: [u8; 3],
    /// Per-vertex colours for `spot-gouraud` ([`normal_color`] of each
    /// normal; baked by build.rs).
    pub colors: &'a [Rgb888],
}

/// The `spot-gouraud` colour of a vertex: its unit normal mapped from
/// `-1..1` to `0..255` per axis (x red, y green, z blue).
#[allow(dead_code)]
pub fn normal_color(n: Vec3) -> Rgb888 {
    let c = |x: f32| ((x * 0.5 + 0.5) * 255.0 + 0.5).clamp(0.0, 255.0) as u8;
    Rgb888::new(c(n.x), c(n.y), c(n.z))
}

/// Object to clip space for a `width x height` frame (45 degree vertical
/// field of view); with `herd`, world to clip space (60 degrees, as the
/// host's `spots` scene; each Spot's [`herd_model`] goes on the right).
pub fn mvp(width: u32, height: u32) -> Mat4 {
    #[cfg(feature = "herd")]
    return herd_view(width, height, HERD_EYE);
    #[cfg(not(feature = "herd"))]
    return Mat4::perspective(radians(45.0), width as f32 / height as f32, 1.0, 6.0)
        * Mat4::look_at(EYE, TARGET, Vec3::new(0.0, 1.0, 0.0));
}

/// Spots a side of the `herd` builds' grid: the host's `spots` scene
/// (`bench --scene spots`, `SPOTS_GRID`), 100 Spots.
#[allow(dead_code)]
pub const HERD_SIDE: usize = 10;

/// Spots in the herd.
#[allow(dead_code)]
pub const HERD_SPOTS: usize = HERD_SIDE * HERD_SIDE;

/// The grid's spacing between Spots' centres (the host's
/// `SPOTS_SPACING`; Spot's box is 0.94 wide and 1.72 long).
#[allow(dead_code)]
const HERD_SPACING: f32 = 2.0;

/// The herd's camera: the host's `spots_camera(0, 64, 10)`, on a circle
/// round the grid one spacing outside it, at eye height (Spot's feet at
/// -0.74, its back at about 0.5), looking at the grid's centre, so the
/// nearest row hides most of the rows behind it.
#[allow(dead_code)]
pub const HERD_EYE: Vec3 = Vec3::new(11.532041, 0.45, 0.566531);
/// The point the herd's camera looks at: the middle of the herd.
#[allow(dead_code)]
pub const HERD_TARGET: Vec3 = Vec3::new(0.0, 0.1, 0.0);

/// Grid cell `c` (row-major) of the herd: its centre `(x, z)` on the
/// ground and Spot's turn about the vertical axis there, in radians (the
/// host's `SpotGrid::scene`: the same hash of the cell gives the turn).
#[allow(dead_code)]
const fn herd_cell(c: usize) -> (f32, f32, f32) {
    let half = (HERD_SIDE as f32 - 1.0) * 0.5 * HERD_SPACING;
    let (i, j) = (c / HERD_SIDE, c % HERD_SIDE);
    let h = (c as u32).wrapping_mul(2_654_435_761);
    let yaw = (h >> 8) as f32 / 16_777_216.0 * core::f32::consts::TAU;
    (
        i as f32 * HERD_SPACING - half,
        j as f32 * HERD_SPACING - half,
        yaw,
    )
}

/// The herd's cells front to back as the camera sees them (by the
/// distance from [`HERD_EYE`] to each cell's centre, ties by cell): the
/// strips draw the nearest first, what occlusion culling needs to hide the
/// rest. Sorted at compile time, for build.rs (the firmware sorts at run
/// time with the same function, for its sweep's cameras too).
#[allow(dead_code)]
const HERD_ORDER: [u8; HERD_SPOTS] = herd_order(HERD_EYE);

/// The herd's cells front to back from `eye` (by the distance from `eye`
/// to each cell's centre on the ground, ties by cell).
#[allow(dead_code)]
pub const fn herd_order(eye: Vec3) -> [u8; HERD_SPOTS] {
    let mut d = [0.0f32; HERD_SPOTS];
    let mut order = [0u8; HERD_SPOTS];
    let mut c = 0;
    while c < HERD_SPOTS {
        let (x, z, _) = herd_cell(c);
        let (dx, dz) = (x - eye.x, z - eye.z);
        d[c] = dx * dx + dz * dz;
        order[c] = c as u8;
        c += 1;
    }
    // Insertion sort, stable: equal distances keep the cells' order.
    let mut a = 1;
    while a < HERD_SPOTS {
        let mut b = a;
        while b > 0 && d[order[b - 1] as usize] > d[order[b] as usize] {
            let t = order[b - 1];
            order[b - 1] = order[b];
            order[b] = t;
            b -= 1;
        }
        a += 1;
    }
    order
}

/// Object to world space of the herd's `k`-th Spot front to back: turned
/// about the vertical axis, then moved to its cell (normals and lights
/// stay in object space).
#[allow(dead_code)]
pub fn herd_model(k: usize) -> Mat4 {
    herd_cell_model(HERD_ORDER[k % HERD_SPOTS] as usize)
}

/// Object to world space of the Spot in grid cell `c` (row-major).
#[allow(dead_code)]
pub fn herd_cell_model(c: usize) -> Mat4 {
    let (x, z, yaw) = herd_cell(c % HERD_SPOTS);
    Mat4::translation(Vec3::new(x, 0.0, z)) * Mat4::rotation_y(yaw)
}

/// The cosine of `i` sixty-fourths of a turn, `i` in `0..=16` (a quarter
/// turn), rounded to `f32` (`cos(i pi / 32)`; the eighth of a turn is
/// `FRAC_1_SQRT_2`, the quarter exactly 0).
#[allow(dead_code)]
const QUARTER: [f32; 17] = [
    1.0,
    0.995_184_7,
    0.980_785_25,
    0.956_940_35,
    0.923_879_5,
    0.881_921_3,
    0.831_469_6,
    0.773_010_43,
    core::f32::consts::FRAC_1_SQRT_2,
    0.634_393_3,
    0.555_570_24,
    0.471_396_74,
    0.382_683_43,
    0.290_284_66,
    0.195_090_32,
    0.098_017_14,
    0.0,
];

/// `(cos, sin)` of `j` sixty-fourths of a turn, `j` in `0..64` (taken mod
/// 64): the sweeps' directions, from [`QUARTER`] by the quarter turns'
/// symmetries (`0.0 - x` negates without making a `-0.0`).
#[allow(dead_code)]
fn turn(j: usize) -> (f32, f32) {
    let i = j % 16;
    let (c, s) = (QUARTER[i], QUARTER[16 - i]);
    match j / 16 % 4 {
        0 => (c, s),
        1 => (0.0 - s, c),
        2 => (0.0 - c, 0.0 - s),
        _ => (s, 0.0 - c),
    }
}

/// Cameras of the `herd-occlusion` builds' sweep: [`HERD_EYE`] turned
/// about the vertical axis through the herd's centre by a sixty-fourth of
/// a turn at a time: the host's 64 cameras, `spots_camera(j, 64, 10)` for
/// `j` in `0..64` (to `f32` rounding), each looking at [`HERD_TARGET`].
#[allow(dead_code)]
pub const HERD_SWEEP: usize = 64;

/// The eye of the herd sweep's camera `j` (see [`HERD_SWEEP`]).
#[allow(dead_code)]
pub fn herd_sweep_eye(j: usize) -> Vec3 {
    let (c, s) = turn(j);
    let (x, z) = (HERD_EYE.x, HERD_EYE.z);
    Vec3::new(x * c - z * s, HERD_EYE.y, x * s + z * c)
}

/// World to clip space for the herd seen from `eye` (60 degrees, as the
/// host's `spots` scene), looking at [`HERD_TARGET`].
#[allow(dead_code)]
pub fn herd_view(width: u32, height: u32, eye: Vec3) -> Mat4 {
    Mat4::perspective(radians(60.0), width as f32 / height as f32, 0.5, 50.0)
        * Mat4::look_at(eye, HERD_TARGET, Vec3::new(0.0, 1.0, 0.0))
}

/// Cameras of the cluster builds' sweep: eyes on the circle through
/// [`EYE`] about the vertical axis through [`TARGET`], a sixty-fourth of a
/// turn (5.625 degrees) apart, at [`EYE`]'s height; the first is [`EYE`]
/// itself (the sweep of 8 cameras before 2026-12-07 drew every eighth).
#[allow(dead_code)]
pub const SWEEP: usize = 64;

/// Object to clip space from the sweep's camera `k` (see [`SWEEP`]).
#[allow(dead_code)]
pub fn sweep_mvp(width: u32, height: u32, k: usize) -> Mat4 {
    // From (0, -1), the direction from `TARGET` to `EYE`.
    let (sx, sz) = turn(k % SWEEP + 48);
    let r = TARGET.z - EYE.z;
    let eye = Vec3::new(TARGET.x + r * sx, EYE.y, TARGET.z + r * sz);
    Mat4::perspective(radians(45.0), width as f32 / height as f32, 1.0, 6.0)
        * Mat4::look_at(eye, TARGET, Vec3::new(0.0, 1.0, 0.0))
}

/// Ambient plus one white-ish key light above the viewer's left, in
/// object space (the viewer looks along +z, so its left is +x).
#[allow(dead_code)]
pub fn lighting() -> Result<Lighting, Error> {
    let key = DirectionalLight {
        direction: Vec3::new(0.5, 0.7, -1.0),
        color: [0.85, 0.85, 0.85],
    };
    Lighting::new([0.25, 0.25, 0.25], &[key], EYE - TARGET)
}

/// The surface of the lit variants: a faint highlight.
#[allow(dead_code)]
pub const MATERIAL: Material = Material {
    specular: [0.2, 0.2, 0.2],
    shininess: 24,
};

/// Triangles per run of the firmware's mesh (see `spot_chunks` in
/// build.rs): each run has its own bounding sphere (16 bytes of flash), so
/// a strip skips the runs it cannot touch. Measured on the M4F,
/// `spot-flat`, 16-row strips: 44.4 M instructions a frame unchunked, 16.9 M
/// with runs of 16, 17.2 M with 32, 18.8 M with 64, 21.4 M with 128.
#[allow(dead_code)]
pub const CHUNK_TRIANGLES: usize = 32;

/// What draws the frame: the firmware's strip loop, or build.rs's one
/// `Frame`.
pub trait Draw {
    type Out;
    fn draw<const N: usize, A: Attributes<N> + Copy, F: FragmentShader<N> + Copy>(
        self,
        mesh: &Mesh<'_, A>,
        fragment: F,
    ) -> Self::Out;
}

fn mesh<'a, A>(model: &Model<'a>, attributes: A) -> Mesh<'a, A> {
    Mesh {
        positions: model.positions,
        indices: model.indices,
        attributes,
        bounds: None,
    }
}

/// Draws `model` with the shading the features select, through `d`.
#[allow(clippy::needless_return)]
pub fn draw<D: Draw>(model: &Model<'_>, d: D) -> Result<D::Out, Error> {
    #[allow(unused_variables)]
    let [r, g, b] = model.diffuse;
    #[allow(unused_variables)]
    let grey = Rgb888::new(r, g, b);
    #[cfg(feature = "spot-flat")]
    return Ok(d.draw(&mesh(model, MeshColors::Uniform(grey)), VertexColor));
    #[cfg(feature = "spot-gouraud")]
    return Ok(d.draw(
        &mesh(model, MeshColors::PerVertex(model.colors)),
        VertexColor,
    ));
    #[cfg(feature = "spot-lit")]
    {
        let lighting = lighting()?;
        let lit = LitColors {
            base: MeshColors::Uniform(grey),
            normals: model.normals,
            lighting: &lighting,
            material: MATERIAL,
        };
        return Ok(d.draw(&mesh(model, lit), VertexColor));
    }
    #[cfg(any(
        feature = "spot-textured",
        feature = "spot-textured-lit",
        feature = "spot-phong"
    ))]
    let texture = Texture::new(model.texture, model.texture_width, model.texture_height)?;
    #[cfg(feature = "spot-textured")]
    {
        let attributes = ColorUv {
            color: MeshColors::Uniform(Rgb888::WHITE),
            uvs: model.uvs,
        };
        return Ok(d.draw(&mesh(model, attributes), Textured { texture }));
    }
    #[cfg(feature = "spot-textured-lit")]
    {
        let lighting = lighting()?;
        let attributes = ColorUv {
            color: LitColors {
                base: MeshColors::Uniform(Rgb888::WHITE),
                normals: model.normals,
                lighting: &lighting,
                material: MATERIAL,
            },
            uvs: model.uvs,
        };
        return Ok(d.draw(&mesh(model, attributes), Textured { texture }));
    }
    #[cfg(feature = "spot-phong")]
    {
        let lighting = lighting()?;
        let attributes = ColorUvNormal {
            color: MeshColors::Uniform(Rgb888::WHITE),
            uvs: model.uvs,
            normals: model.normals,
        };
        let phong = Phong {
            lighting: &lighting,
            material: MATERIAL,
            texture,
        };
        return Ok(d.draw(&mesh(model, attributes), phong));
    }
}
