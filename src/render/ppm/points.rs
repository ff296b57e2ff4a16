//! A pass's visible points as arrays (structure of arrays): [`Reach`] — position and both
//! search radii², all the spatial index and the photon pass's candidate test read, 32 bytes —
//! and [`Shade`] — slot, normal and weight, read only when a photon is inside, 28 bytes (f32:
//! a deposit's flux is summed in f32 anyway). One array of [`VisiblePoint`]s (88 bytes) plus
//! a packed copy of positions and radii for the photon pass (40) held 128 bytes a point: at
//! 1920×1080 the split saves 140 MiB of a stochastic render's peak. A third array, of
//! [`GlossyPoint`]s, is there only when the scene has glossy materials: a point on a glossy
//! surface weighs each photon by the BSDF for the photon's direction.

use glam::{DVec3, Vec3};
use rayon::iter::Either;
use rayon::prelude::*;

#[cfg(test)]
use super::estimate::Estimate;
use super::estimate::Slot;
use super::sweep::SWEEP_BLOCK;
use super::visible::{point_weight, GlossyPoint, VisiblePoint};

/// A search sphere the spatial indices are built over: a centre and the radius² that reaches
/// farthest.
pub trait SearchSphere {
    /// The centre.
    fn centre(&self) -> DVec3;
    /// The largest radius² a photon is looked for within.
    fn reach2(&self) -> f64;
}

impl SearchSphere for VisiblePoint {
    fn centre(&self) -> DVec3 {
        self.position
    }

    fn reach2(&self) -> f64 {
        self.radius2
    }
}

/// A visible point's position and its slot's two search radii² (primary, indirect), copied
/// from the slot before each photon pass ([`VisiblePoints::set_radii`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reach {
    /// Position on the diffuse surface.
    pub position: DVec3,
    /// Radius² of the primary and the indirect estimate (0 when that estimate is off), in f32
    /// as the estimates hold them.
    pub radius2: [f32; 2],
}

impl SearchSphere for Reach {
    #[inline]
    fn centre(&self) -> DVec3 {
        self.position
    }

    #[inline]
    fn reach2(&self) -> f64 {
        self.radius2[0].max(self.radius2[1]) as f64
    }
}

/// What a deposit needs of a visible point beyond its [`Reach`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shade {
    /// The statistics slot the point gathers into ([`Shade::NONE`]: no point).
    pub slot: u32,
    /// Unit normal facing the eye path.
    pub normal: Vec3,
    /// Path throughput × BRDF (ρ/π), RGB.
    pub weight: Vec3,
}

impl Shade {
    /// The slot of a placeholder for a pixel whose eye path found no diffuse surface.
    pub const NONE: u32 = u32::MAX;

    /// A placeholder for a pixel without a point.
    pub const EMPTY: Shade = Shade {
        slot: Self::NONE,
        normal: Vec3::ZERO,
        weight: Vec3::ZERO,
    };
}

/// The visible points of a pass: `reach[k]`, `shade[k]` and, when the scene has glossy
/// materials, `glossy[k]` describe point `k`.
#[derive(Clone, Debug, Default)]
pub struct VisiblePoints {
    /// Positions and radii.
    pub reach: Vec<Reach>,
    /// Slots, normals and weights.
    pub shade: Vec<Shade>,
    /// Each point's glossy lobes (`None` on a surface without); empty when no point can have
    /// any.
    pub glossy: Vec<Option<GlossyPoint>>,
}

/// One pixel's place among a stochastic pass's points, which its eye path writes its visible
/// point into ([`VisiblePoints::places_mut`]).
pub struct Place<'a> {
    reach: &'a mut Reach,
    shade: &'a mut Shade,
    /// Room for the point's glossy lobes, when the points have any.
    glossy: Option<&'a mut Option<GlossyPoint>>,
}

impl Place<'_> {
    /// Empties this place (it held a point copied from an earlier pass that is to be traced
    /// again, [`super::reuse`]).
    pub fn clear(&mut self) {
        *self.reach = Reach::default();
        *self.shade = Shade::EMPTY;
        if let Some(g) = self.glossy.as_deref_mut() {
            *g = None;
        }
    }

    /// Puts `vp` here (once: a chosen path ends at one point).
    pub fn set(&mut self, vp: &VisiblePoint) {
        debug_assert!(self.shade.slot == Shade::NONE, "a chosen path ends once");
        (*self.reach, *self.shade) = split(vp);
        if let Some(g) = self.glossy.as_deref_mut() {
            *g = vp.glossy;
        }
    }
}

/// Splits a visible point into its two parts (radii left at 0 until [`VisiblePoints::set_radii`]).
pub fn split(vp: &VisiblePoint) -> (Reach, Shade) {
    (
        Reach {
            position: vp.position,
            radius2: [0.0; 2],
        },
        Shade {
            slot: vp.slot,
            normal: vp.normal.as_vec3(),
            weight: vp.weight.as_vec3(),
        },
    )
}

impl VisiblePoints {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.reach.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.reach.is_empty()
    }

    /// `n` placeholders (no point), with room for glossy lobes if `glossy`, keeping the
    /// arrays' capacity.
    pub fn reset(&mut self, n: usize, glossy: bool) {
        self.reach.clear();
        self.reach.resize(n, Reach::default());
        self.shade.clear();
        self.shade.resize(n, Shade::EMPTY);
        self.glossy.clear();
        if glossy {
            self.glossy.resize(n, None);
        } else {
            self.glossy.shrink_to_fit();
        }
    }

    /// What point `k` turns flux arriving from `wi` (away from the surface; a unit vector)
    /// into: its weight (throughput × the diffuse lobe) when `wi` is above the surface, plus
    /// throughput × its glossy lobes for `wi` (which may take light from below).
    #[inline]
    pub fn weight(&self, k: usize, wi: DVec3) -> DVec3 {
        let s = &self.shade[k];
        let glossy = self.glossy.get(k).and_then(Option::as_ref);
        point_weight(s.weight.as_dvec3(), s.normal.as_dvec3(), glossy, wi)
    }

    /// Whether point `k` gathers light arriving from below its surface too (a rough
    /// dielectric's refraction).
    #[inline]
    pub fn two_sided(&self, k: usize) -> bool {
        matches!(self.glossy.get(k), Some(Some(g)) if g.lobes.two_sided())
    }

    /// Every place in order, in parallel, for an eye pass to write each pixel's point into
    /// ([`VisiblePoints::reset`] first).
    pub fn places_mut(&mut self) -> impl IndexedParallelIterator<Item = Place<'_>> {
        let glossy = if self.glossy.is_empty() {
            Either::Right((0..self.reach.len()).into_par_iter().map(|_| None))
        } else {
            Either::Left(self.glossy.par_iter_mut().map(Some))
        };
        self.reach
            .par_iter_mut()
            .zip(self.shade.par_iter_mut())
            .zip(glossy)
            .map(|((reach, shade), glossy)| Place { reach, shade, glossy })
    }

    /// Makes this a copy of `other`, in the memory this one holds.
    pub fn copy_from(&mut self, other: &VisiblePoints) {
        self.reach.clone_from(&other.reach);
        self.shade.clone_from(&other.shade);
        self.glossy.clone_from(&other.glossy);
    }

    /// Removes the placeholders, keeping the points' order.
    pub fn drop_empty(&mut self) {
        let mut kept = 0;
        let glossy = !self.glossy.is_empty();
        for k in 0..self.shade.len() {
            if self.shade[k].slot != Shade::NONE {
                self.reach[kept] = self.reach[k];
                self.shade[kept] = self.shade[k];
                if glossy {
                    self.glossy[kept] = self.glossy[k];
                }
                kept += 1;
            }
        }
        self.reach.truncate(kept);
        self.shade.truncate(kept);
        if glossy {
            self.glossy.truncate(kept);
        }
    }

    /// Puts the points in `order` (place `i` gets point `order[i]`; used up, as the grid's
    /// build returns it), in place: no array is copied. The arrays are permuted at once on as
    /// many threads as there are (each but the first with a copy of `order`, 4 bytes a
    /// point), each following the permutation's cycles.
    pub fn permute(&mut self, order: &mut [u32]) {
        let mut copy = order.to_vec();
        let glossy = &mut self.glossy;
        let mut glossy_order = (!glossy.is_empty()).then(|| order.to_vec());
        rayon::join(
            || permute_in_place(&mut self.reach, order),
            || {
                rayon::join(
                    || permute_in_place(&mut self.shade, &mut copy),
                    || {
                        if let Some(o) = &mut glossy_order {
                            permute_in_place(glossy, o);
                        }
                    },
                )
            },
        );
    }

    /// Copies each point's slot's radii² into its reach; returns the largest radius² of each
    /// estimate (0 without points). In parallel, [`SWEEP_BLOCK`] points a task: every pass
    /// does it before its photons, and each point reads its slot from wherever it lies. The
    /// largest of a set of radii does not depend on the order it is taken in, so neither does
    /// the result.
    pub fn set_radii(&mut self, slots: &[Slot]) -> [f32; 2] {
        let largest = |reach: &mut [Reach], shade: &[Shade]| {
            let mut largest = [0.0f32; 2];
            for (r, s) in reach.iter_mut().zip(shade) {
                let slot = &slots[s.slot as usize];
                r.radius2 = [slot.primary.radius2() as f32, slot.indirect.radius2() as f32];
                largest = [largest[0].max(r.radius2[0]), largest[1].max(r.radius2[1])];
            }
            largest
        };
        self.reach
            .par_chunks_mut(SWEEP_BLOCK)
            .zip(self.shade.par_chunks(SWEEP_BLOCK))
            .map(|(reach, shade)| largest(reach, shade))
            .reduce(|| [0.0f32; 2], |a, b| [a[0].max(b[0]), a[1].max(b[1])])
    }
}

/// Puts `items` in `order` (place `i` gets item `order[i]`), in place, following the
/// permutation's cycles; `order` is used up.
fn permute_in_place<T: Copy>(items: &mut [T], order: &mut [u32]) {
    const DONE: u32 = u32::MAX;
    for i in 0..order.len() {
        if order[i] == DONE {
            continue;
        }
        let first = items[i];
        let mut j = i;
        loop {
            let k = order[j] as usize;
            order[j] = DONE;
            if k == i {
                items[j] = first;
                break;
            }
            items[j] = items[k];
            j = k;
        }
    }
}

impl FromIterator<VisiblePoint> for VisiblePoints {
    fn from_iter<I: IntoIterator<Item = VisiblePoint>>(iter: I) -> Self {
        let points: Vec<VisiblePoint> = iter.into_iter().collect();
        let (reach, shade) = points.iter().map(split).unzip();
        let glossy = if points.iter().any(|p| p.glossy.is_some()) {
            points.iter().map(|p| p.glossy).collect()
        } else {
            Vec::new()
        };
        Self { reach, shade, glossy }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placeholders_are_dropped_in_order_and_radii_come_from_the_slots() {
        let vp = |slot, x| VisiblePoint {
            slot,
            position: DVec3::new(x, 0.0, 0.0),
            normal: DVec3::Z,
            weight: DVec3::ONE,
            radius2: 0.0,
            glossy: None,
        };
        let mut points = VisiblePoints::default();
        points.reset(4, false);
        for (k, x) in [(1usize, 1.0), (3, 3.0)] {
            (points.reach[k], points.shade[k]) = split(&vp(k as u32, x));
        }
        points.drop_empty();
        assert_eq!(points.len(), 2);
        assert_eq!(points.shade[0].slot, 1);
        assert_eq!(points.reach[1].position.x, 3.0);
        let mut slots: Vec<Slot> = (0..4).map(Slot::new).collect();
        slots[3].primary = Estimate::empty(4.0);
        slots[3].indirect = Estimate::empty(9.0);
        assert_eq!(points.set_radii(&slots), [4.0, 9.0]);
        assert_eq!(points.reach[1].radius2, [4.0, 9.0]);
        assert_eq!(points.reach[1].reach2(), 9.0);
        assert_eq!(points.reach[0].reach2(), 0.0);
    }

    /// A glossy point's lobes follow it when placeholders are dropped and when points are
    /// permuted, and its weight for a photon's direction adds the lobe's to the diffuse
    /// weight; a point without lobes weighs every direction alike.
    #[test]
    fn glossy_lobes_follow_their_points() {
        use crate::render::bsdf::{phong, Glossy};
        let lobes = Glossy::Phong {
            specular: 0.5,
            shininess: 10.0,
        };
        let vp = |slot: u32, glossy: bool| VisiblePoint {
            slot,
            position: DVec3::new(slot as f64, 0.0, 0.0),
            normal: DVec3::Z,
            weight: DVec3::splat(0.1),
            radius2: 0.0,
            glossy: glossy.then_some(GlossyPoint {
                throughput: Vec3::splat(2.0),
                wo: DVec3::new(0.6, 0.0, 0.8).as_vec3(),
                lobes,
            }),
        };
        let mut points = VisiblePoints::default();
        points.reset(6, true);
        for k in [1usize, 2, 4, 5] {
            let p = vp(k as u32, k % 2 == 0);
            (points.reach[k], points.shade[k]) = split(&p);
            points.glossy[k] = p.glossy;
        }
        points.drop_empty();
        assert_eq!(points.glossy.len(), 4);
        points.permute(&mut [3, 2, 0, 1]);
        let slots: Vec<u32> = points.shade.iter().map(|s| s.slot).collect();
        assert_eq!(slots, [5, 4, 1, 2]);
        for (k, s) in points.shade.iter().enumerate() {
            assert_eq!(points.glossy[k].is_some(), s.slot % 2 == 0, "point {k}");
        }
        // The mirror direction of wo, and one away from it.
        let (mirror, off) = (DVec3::new(-0.6, 0.0, 0.8), DVec3::Z);
        let expected = |wi: DVec3| 0.1 + 2.0 * phong(0.5, 10.0, DVec3::Z, DVec3::new(0.6, 0.0, 0.8), wi);
        for wi in [mirror, off] {
            let glossy = points.weight(1, wi);
            assert!((glossy.x - expected(wi)).abs() < 1e-5, "{glossy} for {wi}");
            assert!((points.weight(2, wi).x - 0.1).abs() < 1e-7);
        }
        assert!(points.weight(1, mirror).x > 2.0 * points.weight(1, off).x);
    }

    /// Putting the points in an order of several cycles moves each point where the order says.
    #[test]
    fn permuting_moves_each_point_where_the_order_says() {
        let n = 1000u32;
        let mut points: VisiblePoints = (0..n)
            .map(|k| VisiblePoint {
                slot: k,
                position: DVec3::new(k as f64, 0.0, 0.0),
                normal: DVec3::Z,
                weight: DVec3::ONE,
                radius2: 0.0,
                glossy: None,
            })
            .collect();
        // Cycles of several lengths: k ↦ 7k mod 1000 on the units, fixed points elsewhere.
        let order: Vec<u32> = (0..n)
            .map(|k| if k % 2 == 1 && k % 5 != 0 { k * 7 % n } else { k })
            .collect();
        points.permute(&mut order.clone());
        for (place, &from) in order.iter().enumerate() {
            assert_eq!(points.shade[place].slot, from);
            assert_eq!(points.reach[place].position.x, from as f64);
        }
    }
}
