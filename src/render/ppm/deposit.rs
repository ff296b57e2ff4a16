//! Handing photons' flux to the visible points in the order of the grid's cells, many
//! photons at a time: where photons meet diffuse surfaces is recorded while they are traced
//! ([`Hit`]s, gathered in a [`Window`]), the window's hits are sorted by cell
//! ([`SpatialIndex::sort_key`], Morton order), and groups of sorted hits are handed to the
//! points near them. Consecutive hits then read the same cells' points while they are in
//! cache, where photon by photon nearly every search missed it (the 1.6M points of
//! smallppm's scene at 1024×768 are 50 MiB of positions and 45 MiB of shading, more than
//! the cache). Work is reordered for the memory it reads, as Pharr et al. 1997 ("Rendering
//! complex scenes with memory-coherent ray tracing") reorder rays; the points stay where the
//! grid put them.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::gathered::Gathered;
use super::index::SpatialIndex;
use super::photon::Emitted;
use super::points::VisiblePoints;
use crate::render::control::Control;

/// Deposits one group of hits may hold before they are merged per slot: bounds memory when
/// radii are large (every photon then reaches thousands of points).
const MAX_GROUP_DEPOSITS: usize = 1 << 20;

/// Photons a window holds before it is handed, however few hits they made (a batch is at
/// most this many too, so photons' places fit the 31 bits [`Hit`] keeps for them).
pub(super) const WINDOW_PHOTONS: usize = 1 << 22;

/// Flux handed to a statistics slot: `(slot, flux × point weight, photon count)`, the flux
/// in f32 as the pass sums it (20 bytes a deposit, not 32).
type Deposit = (u32, Vec3, u32);

/// Merges deposits to the same slot, keeping each slot's additions in their order (a stable
/// sort), so the sums depend only on the group's hits, not on threads.
fn compact(deposits: &mut Vec<Deposit>) {
    deposits.sort_by_key(|d| d.0);
    let mut merged: Vec<Deposit> = Vec::with_capacity(deposits.len() / 4);
    for &(slot, flux, count) in deposits.iter() {
        match merged.last_mut() {
            Some(last) if last.0 == slot => {
                last.1 += flux;
                last.2 += count;
            }
            _ => merged.push((slot, flux, count)),
        }
    }
    *deposits = merged;
}

/// Hits a window holds before they are handed (64 bytes each: 32 MiB): the more, the more
/// often consecutive hits share cells; beyond 2^19, twice the memory buys little.
pub(super) const WINDOW_HITS: usize = 1 << 19;

/// Sorted hits handed to the points as one unit of parallel work. Each wave ends when its
/// last group does, so a thread waits for up to one group at every wave's end: groups small
/// beside a wave keep that wait short. Unless a group's deposits outgrow
/// [`MAX_GROUP_DEPOSITS`] and are merged, they are folded in the sorted hits' order whatever
/// the group, so the image does not depend on the group size.
const GROUP: usize = 1024;

/// Groups ([`GROUP`] hits each) handed between two looks at the caller's control, and
/// folded together, per thread: enough to keep every thread busy, few enough that the
/// deposits held at once (a wave's and the one before it, being folded) stay near what the
/// pass held when photons were handed chunk by chunk.
const WAVE_PER_THREAD: usize = 16;

/// What a group of hits handed: deposits, and the window places of the photons that reached
/// a point.
type Handed = (Vec<Deposit>, Vec<u32>);

/// Where a photon met a diffuse surface whose flux is gathered.
#[derive(Clone, Copy, Debug)]
pub(super) struct Hit {
    /// The order it is handed in ([`SpatialIndex::sort_key`] of `p`).
    key: u64,
    /// Where.
    p: DVec3,
    /// The surface's normal, facing the photon ([`snorm`]: it only tells the surface's sides
    /// apart).
    n: [i16; 3],
    /// The direction the photon came from, away from the surface ([`snorm`], within about
    /// 5e-5 radians: a glossy point weighs the photon by it).
    wi: [i16; 3],
    /// The photon's flux (a deposit's flux is summed in f32).
    flux: Vec3,
    /// The photon's place in its window (bits 32–62), the hit's place among the photon's
    /// (bits 1–31), and 1 for an indirect hit (bit 0): unique, and in photon order, so ties
    /// between keys are broken by it and the sort's result depends on the photons only.
    order: u64,
}

impl Hit {
    /// The `nth` hit, at `p` on a surface of normal `n`, of a photon of `flux` that came from
    /// `wi` and is the `photon`th of its window, gathered into the indirect estimate if
    /// `indirect`; `key` places it.
    pub(super) fn new(
        key: u64,
        p: DVec3,
        (n, wi): (DVec3, DVec3),
        flux: DVec3,
        (photon, nth): (u32, u32),
        indirect: bool,
    ) -> Self {
        Self {
            key,
            p,
            n: snorm(n),
            wi: snorm(wi),
            flux: flux.as_vec3(),
            order: (photon as u64) << 32 | (nth as u64) << 1 | indirect as u64,
        }
    }

    /// The estimate it is gathered into: 0 primary, 1 indirect.
    fn estimate(&self) -> usize {
        (self.order & 1) as usize
    }

    /// The photon's place in its window.
    fn photon(&self) -> u32 {
        (self.order >> 32) as u32
    }
}

/// A unit vector in three 16-bit signed fixed-point numbers (each coordinate × 32767, rounded):
/// a few multiplications to write and read, where a two-number octahedral map's divisions and
/// normalisation cost the photon pass 5 % on smallppm's scene.
fn snorm(v: DVec3) -> [i16; 3] {
    let q = |c: f64| (c.clamp(-1.0, 1.0) * 32767.0).round() as i16;
    [q(v.x), q(v.y), q(v.z)]
}

/// [`snorm`]'s vector, within 3e-5 of it in each coordinate (not renormalised).
fn unsnorm(q: [i16; 3]) -> DVec3 {
    DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64) / 32767.0
}

/// Traced photons whose hits are not yet handed: the hits, and where each photon came from,
/// in photon order.
#[derive(Default)]
pub(super) struct Window {
    hits: Vec<Hit>,
    from: Vec<Emitted>,
}

/// How a window's hits are handed: the points and index they search, each estimate's
/// largest radius, the estimates each slot holds.
pub(super) struct Gather<'a> {
    /// The index over `points`.
    pub index: &'a SpatialIndex,
    /// The pass's visible points.
    pub points: &'a VisiblePoints,
    /// Each estimate's largest radius.
    pub radius: [f64; 2],
    /// Estimates per slot: 2, or 1 when the indirect estimate is off.
    pub estimates: usize,
}

impl Window {
    /// Photons it holds: the window place of the next photon traced.
    pub(super) fn photons(&self) -> u32 {
        self.from.len() as u32
    }

    /// Adds a chunk's photons (in order): their hits and where they came from.
    pub(super) fn push(&mut self, mut hits: Vec<Hit>, from: Vec<Emitted>) {
        self.hits.append(&mut hits);
        self.from.extend(from);
    }

    /// Drops what it holds, keeping its memory.
    pub(super) fn clear(&mut self) {
        self.hits.clear();
        self.from.clear();
    }

    /// Whether it holds enough hits to be handed.
    pub(super) fn is_full(&self) -> bool {
        self.hits.len() >= WINDOW_HITS || self.from.len() >= WINDOW_PHOTONS
    }

    /// Sorts the hits and hands them to the points, folding what they handed into `out` in
    /// the sorted order (the same sums for any thread count), wave by wave with `control`
    /// asked between waves; empties the window. `None` when `control` aborts.
    pub(super) fn hand(
        &mut self,
        gather: &Gather,
        out: &mut Gathered,
        control: &mut dyn FnMut() -> Control,
    ) -> Option<()> {
        self.hits.par_sort_unstable_by_key(|h| (h.key, h.order));
        let mut useful = vec![false; self.from.len()];
        // Each wave's deposits are folded while the next wave is handed (on another thread
        // where there is one), in wave order either way.
        let mut fold = |handed: Vec<Handed>| {
            for (deposits, reached) in handed {
                for (at, flux, count) in deposits {
                    out.add(at, flux, count);
                }
                for p in reached {
                    useful[p as usize] = true;
                }
            }
        };
        let mut waiting: Vec<Handed> = Vec::new();
        let wave = GROUP * WAVE_PER_THREAD * rayon::current_num_threads();
        for wave in self.hits.chunks(wave) {
            if control() == Control::Abort {
                return None;
            }
            let folded = std::mem::take(&mut waiting);
            (waiting, ()) = rayon::join(
                || wave.par_chunks(GROUP).map(|group| gather.hand(group)).collect(),
                || fold(folded),
            );
        }
        fold(waiting);
        for (emitted, &useful) in self.from.iter().zip(&useful) {
            if let Some(tally) = &mut out.tally {
                tally.record(emitted.light, emitted.bin, useful);
            }
            out.counts.useful += useful as u64;
        }
        self.clear();
        Some(())
    }
}

impl Gather<'_> {
    /// Hands each of `hits` to every visible point on its side of the surface (either side, for
    /// a point on a rough dielectric) whose search
    /// sphere of the hit's estimate holds it, weighted by the point's BSDF for the photon's
    /// direction: the deposits, and the window places of the photons that reached a point
    /// (repeats possible).
    fn hand(&self, hits: &[Hit]) -> Handed {
        // Two copies of the loop: without glossy points it is the diffuse gather alone.
        if self.points.glossy.is_empty() {
            self.hand_each::<false>(hits)
        } else {
            self.hand_each::<true>(hits)
        }
    }

    /// [`Gather::hand`], weighing photons by glossy lobes if `GLOSSY`.
    fn hand_each<const GLOSSY: bool>(&self, hits: &[Hit]) -> Handed {
        let (reach, shade) = (&self.points.reach, &self.points.shade);
        let mut deposits: Vec<Deposit> = Vec::new();
        let mut reached = Vec::new();
        for h in hits {
            let (p, n, estimate) = (h.p, unsnorm(h.n), h.estimate());
            let wi = if GLOSSY {
                unsnorm(h.wi).normalize()
            } else {
                DVec3::ZERO
            };
            let mut any = false;
            self.index
                .for_candidates(reach, p, self.radius[estimate], &mut |k| {
                    let r = &reach[k as usize];
                    if (r.position - p).length_squared() <= r.radius2[estimate] as f64 {
                        let s = &shade[k as usize];
                        // On the point's side, or through a surface that refracts.
                        let side = s.normal.as_dvec3().dot(n) > 1e-3;
                        if side || (GLOSSY && self.points.two_sided(k as usize)) {
                            let weight = if GLOSSY {
                                self.points.weight(k as usize, wi).as_vec3()
                            } else {
                                s.weight
                            };
                            deposits.push((
                                Gathered::at(self.estimates, s.slot, estimate),
                                weight * h.flux,
                                1,
                            ));
                            any = true;
                        }
                    }
                });
            if any {
                reached.push(h.photon());
            }
            if deposits.len() > MAX_GROUP_DEPOSITS {
                compact(&mut deposits);
            }
        }
        (deposits, reached)
    }
}

#[cfg(test)]
mod tests {
    use rand::Rng;

    use super::*;
    use crate::render::ppm::visible::VisiblePoint;
    use crate::render::ppm::{HashGrid, KdTree};
    use crate::render::rng::stream_rng;

    /// Points on three walls of a box, two estimates with different radii, and hits on the
    /// same walls from photons of several hits each: handed a window at a time in cell order,
    /// every slot's estimate gets exactly the photons a brute-force search finds, with the
    /// same flux up to f32 summation, through the grid and the kd-tree alike; the photons
    /// marked useful are those that reached some point.
    #[test]
    fn hits_handed_in_cell_order_reach_exactly_the_points_in_range() {
        let mut rng = stream_rng(0x9e37_79b9, 0, 0);
        let mut next = || rng.random::<f64>();
        let wall = |k: usize, a: f64, b: f64| match k % 3 {
            0 => (DVec3::new(0.0, a, b), DVec3::X),
            1 => (DVec3::new(a, 0.0, b), DVec3::Y),
            _ => (DVec3::new(a, b, 0.0), DVec3::Z),
        };
        let n = 20_000;
        let mut points: VisiblePoints = (0..n)
            .map(|k| {
                let (position, normal) = wall(k, next() * 10.0, next() * 10.0);
                VisiblePoint {
                    slot: k as u32,
                    position,
                    normal,
                    weight: DVec3::new(next(), next(), next()),
                    radius2: 0.0,
                    glossy: None,
                }
            })
            .collect();
        for r in &mut points.reach {
            r.radius2 = [
                (0.05 + 0.1 * next()).powi(2) as f32,
                (0.3 * next()).powi(2) as f32,
            ];
        }
        let radius = [0, 1].map(|e| {
            let max2 = points.reach.iter().map(|r| r.radius2[e]).fold(0.0f32, f32::max);
            (max2 as f64).sqrt()
        });
        let photons = 3000u32;
        let hits: Vec<(DVec3, DVec3, DVec3, u32, bool)> = (0..photons)
            .flat_map(|photon| (0..1 + photon % 3).map(move |nth| (photon, nth)))
            .map(|(photon, nth)| {
                let (p, n) = wall(photon as usize + nth as usize, next() * 10.0, next() * 10.0);
                let flux = DVec3::new(next(), next(), next());
                (p, n, flux, photon, nth > 0)
            })
            .collect();
        // Brute force: every point of every hit, in f64.
        let mut expected = vec![(DVec3::ZERO, 0u32); 2 * n];
        let mut expected_useful = vec![false; photons as usize];
        for &(p, n, flux, photon, indirect) in &hits {
            let e = indirect as usize;
            for (r, s) in points.reach.iter().zip(&points.shade) {
                let inside = (r.position - p).length_squared() <= r.radius2[e] as f64;
                if inside && s.normal.as_dvec3().dot(n) > 1e-3 {
                    let slot = &mut expected[Gathered::at(2, s.slot, e) as usize];
                    slot.0 += s.weight.as_dvec3() * flux.as_vec3().as_dvec3();
                    slot.1 += 1;
                    expected_useful[photon as usize] = true;
                }
            }
        }
        let grid = {
            let (grid, mut order) = HashGrid::build(&points.reach);
            points.permute(&mut order);
            SpatialIndex::Grid(grid)
        };
        let kd = SpatialIndex::Kd(KdTree::build(&points.reach));
        for index in [&grid, &kd] {
            let gather = Gather {
                index,
                points: &points,
                radius,
                estimates: 2,
            };
            let mut out = Gathered::new(n, 2, None);
            let mut window = Window::default();
            let mut nth = 0;
            let mut chunk = Vec::new();
            for (k, &(p, normal, flux, photon, indirect)) in hits.iter().enumerate() {
                let key = index.sort_key(p);
                chunk.push(Hit::new(key, p, (normal, -normal), flux, (photon, nth), indirect));
                nth += 1;
                if hits.get(k + 1).is_none_or(|h| h.3 != photon) {
                    window.push(std::mem::take(&mut chunk), vec![Emitted { light: 0, bin: 0 }]);
                    nth = 0;
                }
            }
            assert_eq!(window.photons(), photons);
            window
                .hand(&gather, &mut out, &mut || Control::Continue)
                .expect("a window that is not aborted is handed");
            assert_eq!(window.photons(), 0, "handing empties the window");
            for k in 0..n {
                for e in 0..2 {
                    let (flux, count) = expected[2 * k + e];
                    assert_eq!(out.count(k, e), count, "slot {k} estimate {e}");
                    let got = out.flux(k, e);
                    assert!((got - flux).abs().max_element() <= 1e-5 * flux.max_element().max(1.0));
                }
            }
            let useful = expected_useful.iter().filter(|&&u| u).count() as u64;
            assert!(useful > 100, "the test reaches points ({useful} photons)");
            assert_eq!(out.counts.useful, useful);
        }
    }

    /// Directions come back from their 16-bit coordinates within 1e-4 radians once
    /// normalised, and within 1e-4 of unit length without.
    #[test]
    fn directions_survive_their_sixteen_bits() {
        for k in 0..2000 {
            // A spiral over the sphere, and the axes.
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / 2000.0;
            let phi = k as f64 * 2.399_963;
            let s = (1.0 - z * z).sqrt();
            for v in [DVec3::new(s * phi.cos(), s * phi.sin(), z), DVec3::X, -DVec3::Z] {
                let back = unsnorm(snorm(v));
                assert!((back.length() - 1.0).abs() < 1e-4, "{v}");
                assert!(back.normalize().dot(v).clamp(-1.0, 1.0).acos() < 1e-4, "{v}");
            }
        }
    }

    /// The window's memory is what its docs say: 64 bytes a hit.
    #[test]
    fn a_hit_is_64_bytes() {
        assert_eq!(std::mem::size_of::<Hit>(), 64);
    }

    /// A control that aborts stops the handing before anything is folded.
    #[test]
    fn an_aborted_window_hands_nothing() {
        let points: VisiblePoints = [VisiblePoint {
            slot: 0,
            position: DVec3::ZERO,
            normal: DVec3::Z,
            weight: DVec3::ONE,
            radius2: 0.0,
            glossy: None,
        }]
        .into_iter()
        .collect();
        let index = SpatialIndex::Kd(KdTree::build(&points.reach));
        let gather = Gather {
            index: &index,
            points: &points,
            radius: [1.0, 1.0],
            estimates: 1,
        };
        let mut window = Window::default();
        window.push(
            vec![Hit::new(
                0,
                DVec3::ZERO,
                (DVec3::Z, DVec3::Z),
                DVec3::ONE,
                (0, 0),
                false,
            )],
            vec![Emitted { light: 0, bin: 0 }],
        );
        let mut out = Gathered::new(1, 1, None);
        assert!(window.hand(&gather, &mut out, &mut || Control::Abort).is_none());
        assert_eq!(out.count(0, 0), 0);
    }
}
