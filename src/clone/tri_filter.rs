//! A parry3d triangle mesh seen through a triangle filter: closest-point and ray queries on
//! its one BVH skip the triangles the filter rejects, so no second BVH is built per filter.
//! The cloners use it to keep the two sides of a closed mouth or eye apart (a query from an
//! upper-lip vertex never lands on the lower lip) and to skip triangles facing away.

use parry3d::math::Pose;
use parry3d::partitioning::Bvh;
use parry3d::query::details::NormalConstraints;
use parry3d::shape::{CompositeShape, Shape, TriMesh, Triangle, TypedCompositeShape};

/// `mesh` with only the triangles `allowed` accepts (by triangle index).
pub(crate) struct FilteredTriMesh<'a, F: Fn(u32) -> bool> {
    /// The whole mesh and its BVH.
    pub mesh: &'a TriMesh,
    /// Which triangles queries may see.
    pub allowed: F,
}

impl<F: Fn(u32) -> bool> CompositeShape for FilteredTriMesh<'_, F> {
    fn map_part_at(
        &self,
        shape_id: u32,
        f: &mut dyn FnMut(Option<&Pose>, &dyn Shape, Option<&dyn NormalConstraints>),
    ) {
        let _ = self.map_untyped_part_at(shape_id, f);
    }

    fn bvh(&self) -> &Bvh {
        self.mesh.bvh()
    }
}

impl<F: Fn(u32) -> bool> TypedCompositeShape for FilteredTriMesh<'_, F> {
    type PartShape = Triangle;
    type PartNormalConstraints = ();

    fn map_typed_part_at<T>(
        &self,
        i: u32,
        mut f: impl FnMut(Option<&Pose>, &Triangle, Option<&()>) -> T,
    ) -> Option<T> {
        (self.allowed)(i).then(|| f(None, &self.mesh.triangle(i), None))
    }

    fn map_untyped_part_at<T>(
        &self,
        i: u32,
        mut f: impl FnMut(Option<&Pose>, &dyn Shape, Option<&dyn NormalConstraints>) -> T,
    ) -> Option<T> {
        (self.allowed)(i).then(|| f(None, &self.mesh.triangle(i), None))
    }
}
