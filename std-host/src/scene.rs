//! What is drawn: scenes as plain owned data, and the cameras that see them.
//!
//! Design note: a [`Scene`] is meshes, each with its own model-view-projection
//! matrix, plus raw clip-space triangles, in drawing order. It sits below
//! every stage that reads it ([`crate::pipeline`], [`crate::render`],
//! [`crate::bench`]), so data flows one way: scene -> pipeline -> render.
//!
//! Cameras are built here, once: [`look_at`] checks that the eye and the
//! target are distinct finite points and picks the up vector before calling
//! the core's `Mat4::look_at`, which needs one that is not parallel to the
//! view direction: +y, unless the camera looks (almost) straight up or down,
//! where it is -z looking down and +z looking up, so that image right stays
//! +x in both cases. A [`View`] is the frame size plus the optional camera
//! overrides of the command line; `None` keeps the scene's own.

use crate::cliptris::ClipTri;
use microraster::math::radians;
use microraster::pixelcolor::{Rgb888, RgbColor};
use microraster::{BoundingSphere, Mat4, Mesh, MeshColors, Vec3};

/// One mesh to draw, with its own transform to clip space.
#[derive(Clone, Debug)]
pub struct Object {
    /// Object-space positions.
    pub positions: Vec<Vec3>,
    /// Triangles.
    pub indices: Vec<[u32; 3]>,
    /// Colours: per triangle (flat) or per vertex (Gouraud).
    pub colors: ObjectColors,
    /// Bounding sphere for whole-object culling.
    pub bounds: Option<BoundingSphere>,
    /// Object to clip space.
    pub mvp: Mat4,
    /// Cluster culling: the object's triangles are then in cluster order
    /// (see [`crate::cluster::cluster_scene`]).
    pub clusters: Option<std::sync::Arc<ObjectClusters>>,
    /// Normal masks (see [`crate::normal_mask::mask_scene`]); not with
    /// `clusters`.
    pub normal_classes: Option<std::sync::Arc<crate::normal_mask::NormalClassData>>,
    /// An object-space box around the positions: occlusion culling's bound
    /// when given (tighter than the sphere), else the sphere's.
    pub aabb: Option<microraster::occlusion::Aabb>,
    /// Occlusion culling's parts: consecutive runs of triangles from the
    /// first, each with its own box (see [`crate::occlusion::split`]);
    /// tested after the whole object. Triangles after the last part are
    /// drawn without a test.
    pub parts: Option<std::sync::Arc<Vec<crate::occlusion::Part>>>,
    /// Detail culling draws what it drops of this object as boxes in this
    /// colour (`0.0..=255.0`; see [`microraster::DetailFill`]); `None`
    /// drops it. [`detail_boxes`] sets each object's mean colour.
    pub detail_fill: Option<[f32; 3]>,
}

/// An [`Object`]'s varyings: its colours, and the fill of detail
/// culling's boxes.
#[derive(Clone, Copy, Debug)]
pub struct ObjectAttributes<'a> {
    /// The colours.
    pub colors: MeshColors<'a>,
    /// [`Object::detail_fill`].
    pub fill: Option<[f32; 3]>,
}

impl microraster::Attributes<3> for ObjectAttributes<'_> {
    const FINITE: bool = true;
    const DETAIL_FILL: bool = true;

    #[inline]
    fn complete(&self, triangles: usize, vertices: usize) -> bool {
        self.colors.complete(triangles, vertices)
    }
    #[inline]
    fn has(&self, tri: usize, idx: [u32; 3]) -> bool {
        self.colors.has(tri, idx)
    }
    // (Always: a call returns the colour through memory, which the
    // caller read back wider than written, a store-forwarding stall.)
    #[inline(always)]
    fn get(&self, tri: usize, vertex: u32) -> [f32; 3] {
        self.colors.get(tri, vertex)
    }
    #[inline]
    fn detail_fill(&self, _: std::ops::Range<usize>) -> Option<[f32; 3]> {
        self.fill
    }
}

/// Sets every object's [`Object::detail_fill`] to its mean colour (over
/// its triangles, or its vertices for per-vertex colours), so detail
/// culling draws boxes instead of holes.
pub fn detail_boxes(scene: &mut Scene) {
    for o in &mut scene.objects {
        let cs = match &o.colors {
            ObjectColors::PerTriangle(c) | ObjectColors::PerVertex(c) => c,
        };
        let n = cs.len().max(1) as f64;
        let sum = cs.iter().fold([0.0f64; 3], |a, c| {
            [
                a[0] + f64::from(c.r()),
                a[1] + f64::from(c.g()),
                a[2] + f64::from(c.b()),
            ]
        });
        o.detail_fill = Some(sum.map(|v| (v / n) as f32));
    }
}

/// The clusters of an [`Object`] and how they are tested.
#[derive(Clone, Debug)]
pub struct ObjectClusters {
    /// Triangle runs.
    pub clusters: Vec<microraster::Cluster>,
    /// The tree.
    pub nodes: Vec<microraster::ClusterNode>,
    /// The vertex list.
    pub vertex_list: Vec<u32>,
    /// The test.
    pub cull: microraster::ClusterCull,
}

impl ObjectClusters {
    /// The set the core reads.
    pub fn set(&self) -> microraster::ClusterSet<'_> {
        microraster::ClusterSet {
            clusters: &self.clusters,
            nodes: &self.nodes,
            vertices: &self.vertex_list,
        }
    }
}

/// The colours of an [`Object`].
#[derive(Clone, Debug)]
pub enum ObjectColors {
    /// One colour per triangle (flat shading).
    PerTriangle(Vec<Rgb888>),
    /// One colour per vertex (Gouraud shading, perspective-correct).
    PerVertex(Vec<Rgb888>),
}

impl ObjectColors {
    /// As the core's [`MeshColors`].
    pub fn as_mesh_colors(&self) -> MeshColors<'_> {
        match self {
            ObjectColors::PerTriangle(c) => MeshColors::PerTriangle(c),
            ObjectColors::PerVertex(c) => MeshColors::PerVertex(c),
        }
    }
}

impl Object {
    /// As the core's [`Mesh`] with plain colours, no detail fill: a
    /// submission of it never bounds boxes (see
    /// [`microraster::Attributes::DETAIL_FILL`]).
    pub fn plain_mesh(&self) -> Mesh<'_> {
        Mesh {
            positions: &self.positions,
            indices: &self.indices,
            attributes: self.colors.as_mesh_colors(),
            bounds: self.bounds,
        }
    }

    /// As the core's [`Mesh`], with [`Object::detail_fill`].
    pub fn mesh(&self) -> Mesh<'_, ObjectAttributes<'_>> {
        Mesh {
            positions: &self.positions,
            indices: &self.indices,
            attributes: ObjectAttributes {
                colors: self.colors.as_mesh_colors(),
                fill: self.detail_fill,
            },
            bounds: self.bounds,
        }
    }
}

/// Everything to draw in one frame, in drawing order: objects first, then
/// clip-space triangles. Triangle ids count from 0 in that order.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Meshes.
    pub objects: Vec<Object>,
    /// Raw clip-space triangles.
    pub clip_tris: Vec<ClipTri>,
}

impl Scene {
    /// The number of input triangles.
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.indices.len()).sum::<usize>() + self.clip_tris.len()
    }
}

/// Camera and frame settings a scene is built for. `None` takes the
/// scene's own default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Eye position.
    pub eye: Option<[f32; 3]>,
    /// Point looked at.
    pub target: Option<[f32; 3]>,
    /// Vertical field of view in degrees.
    pub fov: Option<f32>,
    /// 1/w depth: [`Mat4::perspective_inv_w`] (window depth `near / w`,
    /// reversed, no far plane) instead of [`Mat4::perspective`].
    pub inv_w: bool,
    /// Portal culling, in a scene with cells and portals (`house`): only
    /// the rooms the eye can see through doors are drawn.
    pub portals: bool,
}

impl View {
    /// A view of `width x height` with the scene's camera.
    pub fn new(width: u32, height: u32) -> View {
        View {
            width,
            height,
            eye: None,
            target: None,
            fov: None,
            inv_w: false,
            portals: false,
        }
    }

    /// The scene's projection: `near` and `far` as the scene chooses, the
    /// far plane dropped for 1/w depth.
    pub fn projection(&self, fov_y_radians: f32, near: f32, far: f32) -> Mat4 {
        projection(self.inv_w, fov_y_radians, self.aspect(), near, far)
    }

    /// Width / height.
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// Whether any camera setting is given.
    pub fn has_camera(&self) -> bool {
        self.eye.is_some() || self.target.is_some() || self.fov.is_some()
    }
}

/// The up vector for a camera at `eye` looking at `target`: +y, or -z / +z
/// when the view is within about 0.06° of straight down / up (where +y
/// would make the look-at basis degenerate).
pub fn up_for(eye: [f32; 3], target: [f32; 3]) -> [f32; 3] {
    let d = [0, 1, 2].map(|k| f64::from(target[k]) - f64::from(eye[k]));
    let dd = d.iter().map(|c| c * c).sum::<f64>();
    // |d x y|^2 = dx^2 + dz^2 = |d|^2 sin^2(angle to y).
    let side = d[0] * d[0] + d[2] * d[2];
    if side > 1e-6 * dd {
        [0.0, 1.0, 0.0]
    } else if d[1] < 0.0 {
        [0.0, 0.0, -1.0]
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// The view matrix of a camera at `eye` looking at `target`, with the up
/// vector of [`up_for`]. Errors if the two points coincide or the distance
/// between them is not finite.
pub fn look_at(eye: [f32; 3], target: [f32; 3]) -> Result<Mat4, String> {
    let d = [0, 1, 2].map(|k| f64::from(target[k]) - f64::from(eye[k]));
    let dd = d.iter().map(|c| c * c).sum::<f64>();
    if !dd.is_finite() || dd <= 0.0 {
        return Err(format!(
            "the camera eye {eye:?} and target {target:?} must be distinct finite points"
        ));
    }
    let v = Vec3::from_array;
    Ok(Mat4::look_at(v(eye), v(target), v(up_for(eye, target))))
}

fn v3(a: [f32; 3]) -> Vec3 {
    Vec3::from_array(a)
}

/// The default scene: four cubes, a colour per face (see [`crate::cubes`]),
/// seen from (0, 3.75, 6.5) towards the origin with a 60° vertical field of
/// view unless `view` says otherwise.
pub fn cubes_scene(view: &View) -> Result<Scene, String> {
    use crate::cubes;
    let eye = view.eye.unwrap_or(cubes::CUBES_EYE);
    let target = view.target.unwrap_or(cubes::CUBES_TARGET);
    let fov = view.fov.unwrap_or(cubes::CUBES_FOV_Y_DEG);
    let proj = view.projection(radians(fov), cubes::CUBES_NEAR, cubes::CUBES_FAR);
    let view_proj = proj * look_at(eye, target)?;
    let mesh = &cubes::MESH;
    let colors = match mesh.attributes {
        MeshColors::PerTriangle(c) => ObjectColors::PerTriangle(c.to_vec()),
        MeshColors::PerVertex(c) => ObjectColors::PerVertex(c.to_vec()),
        MeshColors::Uniform(c) => ObjectColors::PerTriangle(vec![c; mesh.indices.len()]),
    };
    let objects = cubes::CUBE_MODELS
        .iter()
        .map(|ops| Object {
            positions: mesh.positions.to_vec(),
            indices: mesh.indices.to_vec(),
            colors: colors.clone(),
            bounds: mesh.bounds,
            mvp: view_proj * cubes::model_matrix(ops),
            clusters: None,
            normal_classes: None,
            aabb: None,
            parts: None,
            detail_fill: None,
        })
        .collect();
    Ok(Scene {
        objects,
        clip_tris: Vec::new(),
    })
}

/// A mesh seen from `eye` towards `target`, flat-shaded with a head light
/// (Lambert, per triangle, computed here on the host).
/// [`Mat4::perspective`], or for 1/w depth (`inv_w`)
/// [`Mat4::perspective_inv_w`] with the same near plane and none far.
pub fn projection(inv_w: bool, fov_y_radians: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    if inv_w {
        Mat4::perspective_inv_w(fov_y_radians, aspect, near)
    } else {
        Mat4::perspective(fov_y_radians, aspect, near, far)
    }
}

pub fn mesh_scene(
    positions: &[[f32; 3]],
    indices: &[[u32; 3]],
    eye: [f32; 3],
    target: [f32; 3],
    fov_y_deg: f32,
    aspect: f32,
    inv_w: bool,
) -> Result<Scene, String> {
    let view = look_at(eye, target)?;
    let positions: Vec<Vec3> = positions.iter().map(|&p| v3(p)).collect();
    let bounds = BoundingSphere::from_points(&positions);
    let (eye, target) = (v3(eye), v3(target));
    let dist = (target - eye).length();
    let radius = bounds.map(|b| b.radius).unwrap_or(1.0);
    let near = (dist - 2.0 * radius).max(dist * 0.01).max(1e-4);
    let far = (dist + 2.0 * radius).max(near * 2.0);
    let proj = projection(inv_w, radians(fov_y_deg), aspect, near, far);
    let light = (eye - target).normalize();
    let colors = indices
        .iter()
        .map(|t| {
            let p = |k: usize| positions.get(t[k] as usize).copied().unwrap_or(Vec3::ZERO);
            let n = (p(1) - p(0)).cross(p(2) - p(0)).normalize();
            let lambert = n.dot(light).max(0.0);
            let shade = |base: f32| ((0.15 + 0.85 * lambert) * base) as u8;
            Rgb888::new(shade(235.0), shade(215.0), shade(190.0))
        })
        .collect();
    Ok(Scene {
        objects: vec![Object {
            positions,
            indices: indices.to_vec(),
            colors: ObjectColors::PerTriangle(colors),
            bounds,
            mvp: proj * view,
            clusters: None,
            normal_classes: None,
            aabb: None,
            parts: None,
            detail_fill: None,
        }],
        clip_tris: Vec::new(),
    })
}

/// Raw clip-space triangles (white where no colour is given).
pub fn clip_tris_scene(tris: Vec<ClipTri>) -> Scene {
    Scene {
        objects: Vec::new(),
        clip_tris: tris,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn up_is_y_unless_the_view_is_vertical() {
        assert_eq!(up_for([0.0, 3.75, 6.5], [0.0; 3]), [0.0, 1.0, 0.0]);
        assert_eq!(up_for([0.0, 10.0, 0.0], [0.0; 3]), [0.0, 0.0, -1.0]);
        assert_eq!(up_for([0.0, -10.0, 0.0], [0.0; 3]), [0.0, 0.0, 1.0]);
        assert_eq!(up_for([1e-5, 10.0, 0.0], [0.0; 3]), [0.0, 0.0, -1.0]);
        assert_eq!(up_for([0.1, 10.0, 0.0], [0.0; 3]), [0.0, 1.0, 0.0]);
    }

    #[test]
    fn straight_down_view_is_a_usable_basis() {
        let m = look_at([0.0, 10.0, 0.0], [0.0; 3]).unwrap();
        // The target lands on the view axis, 10 units in front (-z).
        let p = m.transform_point(Vec3::ZERO);
        assert!(p.x.abs() < 1e-5 && p.y.abs() < 1e-5 && (p.z + 10.0).abs() < 1e-5);
        // Image right stays +x.
        let r = m.transform_point(Vec3::new(1.0, 0.0, 0.0));
        assert!((r.x - 1.0).abs() < 1e-5, "{r:?}");
        assert!(p.x.is_finite() && r.y.is_finite());
    }

    #[test]
    fn coincident_or_infinite_cameras_are_errors() {
        assert!(look_at([1.0, 2.0, 3.0], [1.0, 2.0, 3.0]).is_err());
        assert!(look_at([f32::NAN, 0.0, 0.0], [0.0; 3]).is_err());
        assert!(look_at([f32::MAX, 0.0, 0.0], [-f32::MAX, 0.0, 0.0]).is_ok());
    }

    #[test]
    fn default_cubes_camera_is_the_shared_one() {
        let s = cubes_scene(&View::new(160, 120)).unwrap();
        let want = crate::cubes::mvps(160, 120);
        for (o, m) in s.objects.iter().zip(&want) {
            assert_eq!(o.mvp, *m);
        }
    }
}
