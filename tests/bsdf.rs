//! Every BSDF against its own promises, as Mitsuba's and pbrt-v4's BSDF tests hold theirs:
//! sampling follows the stated density (a chi-square test over the sphere of directions),
//! nothing reflects more than it receives (a white furnace, and the sampled weights agree with
//! `eval` integrated independently; rough conductors report what single scattering loses),
//! `f` is reciprocal, and the delta lobes obey the mirror law, Snell's law and Fresnel's
//! shares.

use std::f64::consts::{PI, TAU};

use caustic::render::bsdf::{Bsdf, Conductor, Dielectric, Diffuse, Fresnel, Mirror, RoughDielectric};
use caustic::scene::metals;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// `wo` at `theta` degrees from the normal (+z), in the xz plane.
fn outgoing(theta: f64) -> DVec3 {
    let t = theta.to_radians();
    DVec3::new(t.sin(), 0.0, t.cos())
}

fn diffuse(color: f64, specular: f64, shininess: f64) -> Bsdf {
    Bsdf::Diffuse(Diffuse {
        color: DVec3::splat(color),
        specular,
        shininess,
        n: DVec3::Z,
    })
}

/// A rough mirror (Fresnel reflectance 1) of GGX roughness `alpha`, white.
fn rough_mirror(alpha: f64) -> Bsdf {
    Bsdf::Conductor(Conductor {
        color: DVec3::ONE,
        fresnel: Fresnel::One,
        alpha,
        n: DVec3::Z,
    })
}

/// Gold of GGX roughness `alpha`.
fn gold(alpha: f64) -> Bsdf {
    let (eta, k) = metals::named("gold").expect("gold");
    Bsdf::Conductor(Conductor {
        color: DVec3::ONE,
        fresnel: Fresnel::Metal { eta, k },
        alpha,
        n: DVec3::Z,
    })
}

/// Rough glass of index 1.5 and GGX roughness `alpha`, seen from outside (`eta` 1.5) or from
/// inside (`eta` 1/1.5).
fn frosted(alpha: f64, eta: f64) -> Bsdf {
    Bsdf::RoughDielectric(RoughDielectric {
        color: DVec3::ONE,
        eta,
        alpha,
        n: DVec3::Z,
    })
}

/// The upper quantile of χ² with `dof` degrees of freedom at the standard normal's `z`
/// (Wilson & Hilferty 1931).
fn chi2_quantile(dof: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * dof);
    dof * (1.0 - a + z * a.sqrt()).powi(3)
}

const COS_BINS: usize = 20;
const PHI_BINS: usize = 40;

/// The bin of a direction: equal solid angles over the whole sphere (cos θ and φ uniform).
fn bin_of(d: DVec3) -> usize {
    let c = (((d.z + 1.0) / 2.0 * COS_BINS as f64) as usize).min(COS_BINS - 1);
    let phi = d.y.atan2(d.x).rem_euclid(TAU);
    let p = ((phi / TAU * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    c * PHI_BINS + p
}

/// Composite Simpson weights of `intervals` (even) intervals of `[0, 1]`.
fn simpson(intervals: usize) -> Vec<f64> {
    (0..=intervals)
        .map(|i| {
            let w = if i == 0 || i == intervals {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w / (3.0 * intervals as f64)
        })
        .collect()
}

/// Each bin's probability under `pdf`, by Simpson's rule on `sub × sub` intervals per bin in
/// the polar angle θ and in φ (`dω = sin θ dθ dφ`). Nodes even in θ resolve a narrow lobe at
/// a pole (rough glass's refraction narrows its lobe about threefold), where nodes even in
/// cos θ lie 5° apart; and a Phong lobe of exponent 60 at the pole needs Simpson's accuracy
/// (the midpoint rule misplaces 0.08 % of the mass there, which the test counts as samples
/// missing below the surface).
fn expected_shares(pdf: impl Fn(DVec3) -> f64, sub: usize) -> Vec<f64> {
    let dp = TAU / PHI_BINS as f64;
    let weights = simpson(sub);
    let mut shares = vec![0.0; COS_BINS * PHI_BINS];
    for (k, share) in shares.iter_mut().enumerate() {
        let ring = k / PHI_BINS;
        // The ring's cos θ runs over [z0, z1]: θ over [θ1, θ0].
        let z0 = 2.0 * ring as f64 / COS_BINS as f64 - 1.0;
        let z1 = 2.0 * (ring + 1) as f64 / COS_BINS as f64 - 1.0;
        let (t1, t0) = (z1.clamp(-1.0, 1.0).acos(), z0.clamp(-1.0, 1.0).acos());
        let p0 = (k % PHI_BINS) as f64 * dp;
        for (i, wi) in weights.iter().enumerate() {
            // Nodes a hair inside the bin: the density's limit from within it (it jumps to 0
            // at the horizon, a bin edge).
            let theta = t1 + (i as f64 / sub as f64).clamp(1e-9, 1.0 - 1e-9) * (t0 - t1);
            let (z, r) = (theta.cos(), theta.sin());
            for (j, wj) in weights.iter().enumerate() {
                let phi = p0 + j as f64 / sub as f64 * dp;
                *share += wi * wj * r * pdf(DVec3::new(r * phi.cos(), r * phi.sin(), z));
            }
        }
        *share *= (t0 - t1) * dp;
    }
    shares
}

/// Pearson's χ² of `samples` draws of `bsdf.sample(wo)` against `bsdf.pdf(wo, ·)`, with a
/// bin for the samples that fall below the surface (the density's missing mass); bins
/// expecting fewer than 5 are pooled. Returns (χ², degrees of freedom).
fn chi_square(bsdf: &Bsdf, wo: DVec3, samples: usize, seed: u64) -> (f64, f64) {
    let shares = expected_shares(|wi| bsdf.pdf(wo, wi), 64);
    let mut observed = vec![0u64; shares.len() + 1];
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    for _ in 0..samples {
        match bsdf.sample(wo, &mut rng) {
            Some(s) => observed[bin_of(s.wi)] += 1,
            None => observed[shares.len()] += 1,
        }
    }
    let lost = (1.0 - shares.iter().sum::<f64>()).max(0.0);
    let expected: Vec<f64> = shares.iter().chain([&lost]).map(|p| p * samples as f64).collect();
    let (mut chi2, mut dof) = (0.0, -1.0);
    let (mut pooled_e, mut pooled_o) = (0.0, 0.0);
    for (e, o) in expected.iter().zip(&observed) {
        if *e < 5.0 {
            pooled_e += e;
            pooled_o += *o as f64;
            continue;
        }
        chi2 += (*o as f64 - e).powi(2) / e;
        dof += 1.0;
    }
    if pooled_e > 0.0 {
        chi2 += (pooled_o - pooled_e).powi(2) / pooled_e.max(1.0);
        dof += 1.0;
    }
    (chi2, dof)
}

#[test]
fn sampling_follows_the_stated_density() {
    let cases = [
        ("lambert", diffuse(0.8, 0.0, 0.0)),
        ("phong n=1", diffuse(0.5, 0.4, 1.0)),
        ("phong n=10", diffuse(0.5, 0.4, 10.0)),
        ("phong n=60", diffuse(0.6, 0.25, 60.0)),
        ("lobe only", diffuse(0.0, 0.9, 20.0)),
        ("GGX mirror α 0.1", rough_mirror(0.1)),
        ("GGX mirror α 0.3", rough_mirror(0.3)),
        ("GGX mirror α 0.8", rough_mirror(0.8)),
        ("GGX gold α 0.3", gold(0.3)),
        // Refraction narrows a lobe by about 1 − 1/η: below α 0.3 the bins cannot resolve it.
        ("GGX glass α 0.3, outside", frosted(0.3, 1.5)),
        ("GGX glass α 0.6, outside", frosted(0.6, 1.5)),
        ("GGX glass α 0.3, inside", frosted(0.3, 1.0 / 1.5)),
        ("GGX glass α 0.7, inside", frosted(0.7, 1.0 / 1.5)),
    ];
    // 52 tests: the per-test level 1e-4 (z = 3.72) keeps the chance of any false alarm at
    // 0.5 %.
    for (name, bsdf) in cases {
        for theta in [0.0, 35.0, 70.0, 85.0] {
            let (chi2, dof) = chi_square(&bsdf, outgoing(theta), 400_000, 7);
            let limit = chi2_quantile(dof, 3.72);
            eprintln!("{name}, θo {theta}°: χ² {chi2:.1} with {dof} degrees of freedom (limit {limit:.1})");
            assert!(
                chi2 < limit,
                "{name}, θo {theta}°: χ² {chi2} > {limit} ({dof} dof)"
            );
        }
    }
}

#[test]
fn a_density_that_lies_fails_the_chi_square_test() {
    // The same Phong BSDF whose stated lobe is a little wider than what it samples: the test
    // must see it (so the passing cases above mean something).
    let honest = diffuse(0.5, 0.4, 10.0);
    let wider = diffuse(0.5, 0.4, 8.0);
    let wo = outgoing(35.0);
    let shares = expected_shares(|wi| wider.pdf(wo, wi), 24);
    let mut observed = vec![0u64; shares.len()];
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let samples = 400_000;
    for _ in 0..samples {
        if let Some(s) = honest.sample(wo, &mut rng) {
            observed[bin_of(s.wi)] += 1;
        }
    }
    let chi2: f64 = shares
        .iter()
        .zip(&observed)
        .filter(|(p, _)| **p * samples as f64 >= 5.0)
        .map(|(p, o)| (*o as f64 - p * samples as f64).powi(2) / (p * samples as f64))
        .sum();
    let dof = shares.iter().filter(|p| **p * samples as f64 >= 5.0).count() as f64;
    assert!(
        chi2 > chi2_quantile(dof, 3.72),
        "χ² {chi2} did not see the wrong density"
    );
}

/// The directional albedo `∫ f cos dωi` two ways: the mean sampled weight, and uniform
/// hemisphere sampling of `eval` (independent of `sample` and `pdf`).
fn albedo_two_ways(bsdf: &Bsdf, wo: DVec3, n: usize) -> (f64, f64) {
    let mut rng = Pcg64Mcg::seed_from_u64(11);
    let sampled = (0..n)
        .map(|_| bsdf.sample(wo, &mut rng).map_or(0.0, |s| s.weight.x))
        .sum::<f64>()
        / n as f64;
    let uniform = (0..n)
        .map(|_| {
            let z: f64 = rng.random();
            let phi = TAU * rng.random::<f64>();
            let r = (1.0 - z * z).sqrt();
            let wi = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            bsdf.eval(wo, wi).x * z * TAU
        })
        .sum::<f64>()
        / n as f64;
    (sampled, uniform)
}

#[test]
fn a_white_furnace_reflects_at_most_what_it_receives() {
    // A white Lambertian surface reflects everything, exactly, sample by sample.
    let white = diffuse(1.0, 0.0, 0.0);
    let mut rng = Pcg64Mcg::seed_from_u64(1);
    for _ in 0..1000 {
        let s = white.sample(outgoing(40.0), &mut rng).expect("above the surface");
        assert_eq!(s.weight, DVec3::ONE);
    }
    // ρ + ρs = 1: at most 1 at any angle (the lobe loses what falls below the surface), and
    // the sampled weights agree with eval integrated on its own.
    for shininess in [1.0, 10.0, 60.0, 500.0] {
        let bsdf = diffuse(0.5, 0.5, shininess);
        for theta in [0.0, 45.0, 75.0, 89.0] {
            let (sampled, uniform) = albedo_two_ways(&bsdf, outgoing(theta), 400_000);
            eprintln!("ρ 0.5 + ρs 0.5, n {shininess}, θo {theta}°: albedo {sampled:.4} (sampled), {uniform:.4} (uniform); loss {:.4}", 1.0 - sampled);
            assert!(sampled <= 1.0 + 1e-3, "albedo {sampled} > 1");
            let tolerance = if shininess > 100.0 { 0.05 } else { 0.01 };
            assert!(
                (sampled - uniform).abs() < tolerance,
                "{sampled} against {uniform}"
            );
        }
    }
}

/// A rough conductor of Fresnel reflectance 1 loses only what single scattering leaves out
/// (light that would bounce between microfacets): its albedo is at most 1, near 1 when nearly smooth
/// and looking down, and falls with roughness and at grazing angles (printed: the loss across
/// roughness). The sampled weights agree with `eval` integrated on its own, and gold reflects
/// its colour's share.
#[test]
fn a_rough_conductor_reflects_at_most_what_it_receives_and_reports_its_loss() {
    for alpha in [0.05, 0.1, 0.2, 0.5, 1.0] {
        let bsdf = rough_mirror(alpha);
        for theta in [0.0, 45.0, 75.0, 89.0] {
            let (sampled, uniform) = albedo_two_ways(&bsdf, outgoing(theta), 400_000);
            eprintln!("GGX α {alpha}, θo {theta}°: albedo {sampled:.4} (sampled), {uniform:.4} (uniform); loss {:.4}", 1.0 - sampled);
            assert!(sampled <= 1.0 + 1e-9, "albedo {sampled} > 1");
            // Uniform directions rarely find a narrow lobe: compare where they can.
            if alpha >= 0.2 {
                assert!((sampled - uniform).abs() < 0.02, "{sampled} against {uniform}");
            }
            if alpha <= 0.1 && theta <= 45.0 {
                assert!(sampled > 0.97, "α {alpha}, θo {theta}°: albedo {sampled}");
            }
        }
    }
    let [smooth, rough] = [0.05, 1.0].map(|a| albedo_two_ways(&rough_mirror(a), outgoing(75.0), 200_000).0);
    assert!(
        rough < smooth - 0.1,
        "rougher loses more: {rough} against {smooth}"
    );
    // Gold at normal incidence: about its red reflectance 0.94 in red.
    let (red, _) = albedo_two_ways(&gold(0.1), outgoing(0.0), 200_000);
    assert!((red - 0.94).abs() < 0.03, "gold's red albedo {red}");
}

/// Rough glass reflects and refracts at most what it receives: its sampled weights (reflection
/// plus refraction, radiance not scaled by η², as smooth glass does) sum to at most 1, near 1
/// when it is nearly smooth, and agree with `eval` integrated over the whole sphere on its
/// own; seen from inside past the critical angle, only reflection is left.
#[test]
fn rough_glass_reflects_and_refracts_at_most_what_it_receives() {
    let over_sphere = |bsdf: &Bsdf, wo: DVec3, n: usize| {
        let mut rng = Pcg64Mcg::seed_from_u64(13);
        (0..n)
            .map(|_| {
                let z: f64 = 2.0 * rng.random::<f64>() - 1.0;
                let phi = TAU * rng.random::<f64>();
                let r = (1.0 - z * z).sqrt();
                let wi = DVec3::new(r * phi.cos(), r * phi.sin(), z);
                bsdf.eval(wo, wi).x * z.abs() * 2.0 * TAU
            })
            .sum::<f64>()
            / n as f64
    };
    for (alpha, eta) in [(0.05, 1.5), (0.2, 1.5), (0.5, 1.5), (0.2, 1.0 / 1.5)] {
        let bsdf = frosted(alpha, eta);
        for theta in [0.0, 45.0, 75.0] {
            let wo = outgoing(theta);
            let (sampled, _) = albedo_two_ways(&bsdf, wo, 400_000);
            let uniform = over_sphere(&bsdf, wo, 1_000_000);
            eprintln!("GGX glass α {alpha}, η {eta:.3}, θo {theta}°: albedo {sampled:.4} (sampled), {uniform:.4} (uniform)");
            assert!(sampled <= 1.0 + 1e-3, "albedo {sampled} > 1");
            if alpha >= 0.2 {
                assert!((sampled - uniform).abs() < 0.03, "{sampled} against {uniform}");
            }
            if alpha <= 0.05 && eta > 1.0 && theta <= 45.0 {
                assert!(sampled > 0.97, "nearly smooth glass loses {}", 1.0 - sampled);
            }
        }
    }
    // From inside at 60° (past the critical angle 41.8°), every sample reflects.
    let mut rng = Pcg64Mcg::seed_from_u64(2);
    let inside = frosted(0.02, 1.0 / 1.5);
    for _ in 0..1000 {
        if let Some(s) = inside.sample(outgoing(60.0), &mut rng) {
            assert!(s.wi.z > 0.0, "refracted past the critical angle: {}", s.wi);
        }
    }
}

#[test]
fn f_is_reciprocal() {
    let mut rng = Pcg64Mcg::seed_from_u64(5);
    let random_up = |rng: &mut Pcg64Mcg| {
        let z: f64 = rng.random();
        let phi = TAU * rng.random::<f64>();
        let r = (1.0 - z * z).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    };
    for bsdf in [
        diffuse(0.7, 0.0, 0.0),
        diffuse(0.4, 0.5, 25.0),
        rough_mirror(0.3),
        gold(0.2),
        // Reflection by rough glass (both directions above it) is reciprocal; refraction
        // is not without the η² factor.
        frosted(0.3, 1.5),
    ] {
        for _ in 0..10_000 {
            let (a, b) = (random_up(&mut rng), random_up(&mut rng));
            let (fab, fba) = (bsdf.eval(a, b), bsdf.eval(b, a));
            assert!((fab - fba).abs().max_element() <= 1e-12 * fab.max_element().max(1.0));
        }
    }
    // Lambert is ρ/π wherever both directions are above the surface.
    let f = diffuse(0.7, 0.0, 0.0).eval(outgoing(10.0), outgoing(-50.0));
    assert!((f.x - 0.7 / PI).abs() < 1e-15);
}

/// Refraction through rough glass, seen from either side: the value for light crossing one
/// way, times the radiance factor, is the value the surface seen from the far side gives for
/// the crossing the other way (the adjoint BSDF that a light subpath's vertex and a camera
/// subpath's vertex must agree on), and [`Bsdf::pdf_reverse`] is the far side's density of
/// the way back. Above the surface it is the same surface's density with the directions
/// swapped.
#[test]
fn refraction_is_adjoint_and_the_reverse_density_is_the_far_sides() {
    let mut rng = Pcg64Mcg::seed_from_u64(8);
    let random_dir = |rng: &mut Pcg64Mcg, up: bool| {
        let z: f64 = rng.random::<f64>().max(1e-3);
        let phi = TAU * rng.random::<f64>();
        let r = (1.0 - z * z).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), if up { z } else { -z })
    };
    let mut checked = 0;
    for (eta, alpha) in [(1.5, 0.3), (1.0 / 1.5, 0.3), (1.33, 0.1)] {
        let near = frosted(alpha, eta);
        let Bsdf::RoughDielectric(b) = near else {
            unreachable!()
        };
        let far = Bsdf::RoughDielectric(RoughDielectric {
            eta: 1.0 / eta,
            n: -b.n,
            ..b
        });
        for _ in 0..5_000 {
            let (wo, wi) = (random_dir(&mut rng, true), random_dir(&mut rng, false));
            let f = near.eval(wo, wi) * near.radiance_scale(wo, wi);
            let adjoint = far.eval(wi, wo);
            assert!(
                (f - adjoint).abs().max_element() <= 1e-9 * f.max_element().max(1e-3),
                "η {eta}: {f} against {adjoint}"
            );
            assert_eq!(near.pdf_reverse(wo, wi), far.pdf(wi, wo));
            checked += (f.x > 1e-6) as u32;
            let up = random_dir(&mut rng, true);
            assert_eq!(near.pdf_reverse(wo, up), near.pdf(up, wo));
        }
    }
    assert!(checked > 1000, "too few crossings carried light: {checked}");
    // A surface that only reflects takes nothing from beyond it.
    assert_eq!(
        diffuse(0.7, 0.0, 0.0).pdf_reverse(outgoing(10.0), -outgoing(30.0)),
        0.0
    );
}

#[test]
fn delta_lobes_obey_the_mirror_law_snell_and_fresnel() {
    let n = DVec3::Z;
    let mirror = Bsdf::Mirror(Mirror {
        color: DVec3::new(0.9, 0.8, 0.7),
        n,
    });
    let wo = outgoing(30.0);
    let lobes: Vec<_> = mirror.specular_lobes(wo).iter().copied().collect();
    assert_eq!(lobes.len(), 1);
    assert!((lobes[0].wi - DVec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-12);
    assert_eq!((lobes[0].share, lobes[0].tint), (1.0, DVec3::new(0.9, 0.8, 0.7)));
    assert!(!mirror.has_smooth() && mirror.sample(wo, &mut Pcg64Mcg::seed_from_u64(0)).is_none());
    // A smooth metal: the mirror direction, tinted by its Fresnel reflectance at the angle.
    let smooth_gold = gold(0.0);
    let lobes: Vec<_> = smooth_gold.specular_lobes(wo).iter().copied().collect();
    assert_eq!(lobes.len(), 1);
    assert!((lobes[0].wi - DVec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-12);
    let (eta, k) = metals::named("gold").expect("gold");
    let f = caustic::render::bsdf::fresnel_conductor(wo.z, eta.x, k.x);
    assert!((lobes[0].tint.x - f).abs() < 1e-12 && lobes[0].tint.x > lobes[0].tint.z);
    assert!(!smooth_gold.has_smooth() && rough_mirror(0.01).has_smooth());

    let glass = |entering| {
        Bsdf::Dielectric(Dielectric {
            color: DVec3::ONE,
            ior: 1.5,
            entering,
            n,
        })
    };
    // Normal incidence: 4 % reflected, the rest straight through.
    let lobes: Vec<_> = glass(true).specular_lobes(DVec3::Z).iter().copied().collect();
    assert_eq!(lobes.len(), 2);
    assert!((lobes[0].share - 0.04).abs() < 1e-12 && (lobes[0].share + lobes[1].share - 1.0).abs() < 1e-15);
    assert!((lobes[1].wi + DVec3::Z).length() < 1e-12);
    // Snell: the light leaving along wo outside came from inside at sin θt = sin θo / 1.5.
    for theta in [10.0, 40.0, 80.0] {
        let wo = outgoing(theta);
        let lobes: Vec<_> = glass(true).specular_lobes(wo).iter().copied().collect();
        let t = lobes[1].wi;
        assert!(t.z < 0.0);
        let sin_t = (1.0 - t.z * t.z).sqrt();
        assert!((1.5 * sin_t - theta.to_radians().sin()).abs() < 1e-12);
    }
    // From inside past the critical angle (41.8°): total internal reflection, one lobe.
    let lobes: Vec<_> = glass(false)
        .specular_lobes(outgoing(50.0))
        .iter()
        .copied()
        .collect();
    assert_eq!(lobes.len(), 1);
    assert_eq!(lobes[0].share, 1.0);
    // A random choice picks each lobe with its share.
    let lobes = glass(true).specular_lobes(outgoing(70.0));
    let reflect_share = lobes.iter().next().expect("reflection").share;
    let mut rng = Pcg64Mcg::seed_from_u64(9);
    let n_draws = 200_000;
    let reflected = (0..n_draws)
        .filter(|_| lobes.choose(|| rng.random()).expect("a lobe").wi.z > 0.0)
        .count() as f64
        / n_draws as f64;
    let sigma = (reflect_share * (1.0 - reflect_share) / n_draws as f64).sqrt();
    assert!(
        (reflected - reflect_share).abs() < 5.0 * sigma,
        "{reflected} against {reflect_share}"
    );
}
