//! Geometry in `f64`: rays, bounds, Bézier patch maths (rational patches too) and exact
//! ray/patch intersection, spheres, quads and planes, triangle meshes, the BVH, and the
//! container that holds a scene's shapes.

pub mod aabb;
pub mod bezier;
pub mod bpt;
pub mod bspline;
pub mod bvh;
pub mod elevate;
pub mod freeform;
pub mod freeform_trim;
pub mod mesh;
pub mod net;
pub mod patch;
pub mod quad;
pub mod rational;
pub mod ray;
pub mod scene_geometry;
pub mod sphere;
pub mod sphere_batch;
pub mod tessellate;
pub mod trim;
pub mod trimmed;
pub mod usd;
pub mod usd_layer;
pub mod usd_nurbs;

pub use aabb::Aabb;
pub use bezier::BezierPatch;
pub use bpt::{load_bpt, parse_bpt, BptError};
pub use bvh::Bvh;
pub use freeform::{load_freeform_obj, parse_freeform_obj, write_freeform_obj, FreeformError};
pub use mesh::{MeshError, TriangleMesh};
pub use patch::{PatchHit, PatchLeaf, SubdivisionParams, Window};
pub use quad::{Plane, Quad};
pub use ray::{spawn_ray, Ray};
pub use scene_geometry::{
    GeometryBuilder, GeometryStats, Hit, PatchMethod, PatchUpdate, Primitive, SceneGeometry, ShapeRef,
};
pub use sphere::Sphere;
pub use sphere_batch::SphereBatch;
