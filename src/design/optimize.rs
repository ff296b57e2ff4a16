//! The design loop: the photons' landing points are splatted into a grid over the receiver
//! with a Gaussian kernel, compared with the target by a brightness-normalised L2 loss, and
//! the loss's gradient with respect to the control points ([`super::landing`], the chain rule
//! through the splat) drives Adam (Kingma & Ba 2015). A membrane term (squared differences of
//! neighbouring control points' moves) keeps the surface smooth, and every move stays within
//! `±max_height` of where it started, so that the surface can be made.
//!
//! The loss is `N Σ_c (I_c / ΣI − T_c)²` over the `N` cells, `I_c` the splatted power and `T`
//! the target blurred by the same kernel and scaled to sum to 1: 0 when the light draws the
//! target exactly, whatever its brightness. (Against the sharp target, even a surface that
//! draws it exactly would be pushed to sharpen its blurred splat — to over-focus — and the
//! cells along the receiver's edges, whose kernels reach past it, would read as too dark.)

use rayon::prelude::*;

use super::dual::D1;
use super::landing::{land, DesignParams, Receiver};
use super::photons::DesignPhoton;
use crate::scene::Scene;

/// The splat kernel starts this many times wider than `DesignSettings::sigma` and narrows to
/// it over the steps (quadratically): blurred early, the loss sees where light is missing from
/// afar, and a surface does not fold into sharp caustics before the coarse shape is there.
const BLUR_START: f64 = 4.0;

/// How a design runs.
#[derive(Clone, Debug)]
pub struct DesignSettings {
    /// Cells of the receiver grid along `edge_u` and along `edge_v`.
    pub grid: (usize, usize),
    /// The splat kernel's standard deviation, in cells.
    pub sigma: f64,
    /// Weight of the smoothness term.
    pub smoothness: f64,
    /// How far a control point may move from where it started, in scene units.
    pub max_height: f64,
    /// Adam's first step, in scene units; it decays to 0 over `max_steps` (cosine).
    pub step: f64,
    /// The photons are used in this many interleaved subsets, one a step, so that the surface
    /// cannot fit the few rays of one set between which it is free.
    pub subsets: usize,
    /// Stop after this many seconds.
    pub seconds: f64,
    /// Stop after this many steps.
    pub max_steps: usize,
    /// Specular bounces a photon may take.
    pub bounces: usize,
}

/// One step's figures.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct StepReport {
    /// Steps taken before it.
    pub step: usize,
    /// The loss (target term only).
    pub loss: f64,
    /// Seconds since the design began.
    pub elapsed: f64,
    /// Share of the photons that reached the receiver.
    pub landed: f64,
}

/// What a design found: the moves it ended with, and every step's figures.
#[derive(Clone, Debug)]
pub struct DesignOutcome {
    /// Each parameter's move from where it started.
    pub theta: Vec<f64>,
    /// The loss of `theta` over every photon.
    pub final_loss: f64,
    /// The loss of the surface as it started, over every photon.
    pub initial_loss: f64,
    /// Each step.
    pub steps: Vec<StepReport>,
}

/// How many cells from its centre the splat kernel of width `sigma` reaches (three standard
/// deviations): the splat and the target's blur are cut off alike.
fn kernel_reach(sigma: f64) -> i64 {
    (3.0 * sigma).ceil() as i64
}

/// `target` (an `nx × ny` grid) blurred by the splat kernel of width `sigma` (cut off where the
/// splat's is, and at the grid's edges, as the splat is), scaled to sum to 1: what a surface
/// drawing the target exactly splats.
fn blurred(target: &[f64], (nx, ny): (usize, usize), sigma: f64) -> Vec<f64> {
    let reach = kernel_reach(sigma);
    let kernel: Vec<f64> = (-reach..=reach)
        .map(|d| (-((d * d) as f64) / (2.0 * sigma * sigma)).exp())
        .collect();
    let pass = |source: &[f64], along_x: bool| -> Vec<f64> {
        let mut out = vec![0.0; nx * ny];
        for y in 0..ny as i64 {
            for x in 0..nx as i64 {
                let value = source[(y * nx as i64 + x) as usize];
                for (k, w) in (-reach..=reach).zip(&kernel) {
                    let (tx, ty) = if along_x { (x + k, y) } else { (x, y + k) };
                    if (0..nx as i64).contains(&tx) && (0..ny as i64).contains(&ty) {
                        out[(ty * nx as i64 + tx) as usize] += value * w;
                    }
                }
            }
        }
        out
    };
    let mut out = pass(&pass(target, true), false);
    let sum: f64 = out.iter().sum();
    if sum > 0.0 {
        out.iter_mut().for_each(|v| *v /= sum);
    }
    out
}

/// The loss of `landings` against `target` (blurred as the splat is) on the grid, and its
/// derivative with respect to each landing point `(s, t)`.
fn loss_and_slopes(
    landings: &[Option<[D1; 2]>],
    photons: &[DesignPhoton],
    target: &[f64],
    (grid, sigma): ((usize, usize), f64),
) -> (f64, Vec<[f64; 2]>) {
    let (nx, ny) = grid;
    let reach = kernel_reach(sigma);
    let cells = |x: f64, y: f64| {
        let (x0, y0) = (x.round() as i64, y.round() as i64);
        ((y0 - reach).max(0)..=(y0 + reach).min(ny as i64 - 1)).flat_map(move |cy| {
            ((x0 - reach).max(0)..=(x0 + reach).min(nx as i64 - 1)).map(move |cx| (cx, cy))
        })
    };
    let at = |st: &[D1; 2]| (st[0].v * nx as f64 - 0.5, (1.0 - st[1].v) * ny as f64 - 0.5);
    let kernel = |dx: f64, dy: f64| (-(dx * dx + dy * dy) / (2.0 * sigma * sigma)).exp();
    let mut image = vec![0.0; nx * ny];
    for (landing, photon) in landings.iter().zip(photons) {
        if let Some(st) = landing {
            let (x, y) = at(st);
            for (cx, cy) in cells(x, y) {
                image[cy as usize * nx + cx as usize] += photon.weight * kernel(cx as f64 - x, cy as f64 - y);
            }
        }
    }
    let total: f64 = image.iter().sum();
    let n = (nx * ny) as f64;
    if total.is_nan() || total <= 0.0 {
        return (
            n * target.iter().map(|t| t * t).sum::<f64>(),
            vec![[0.0; 2]; landings.len()],
        );
    }
    let g: Vec<f64> = image
        .iter()
        .zip(target)
        .map(|(i, t)| 2.0 * n * (i / total - t))
        .collect();
    let loss = image
        .iter()
        .zip(target)
        .map(|(i, t)| n * (i / total - t).powi(2))
        .sum();
    let shared: f64 = g.iter().zip(&image).map(|(g, i)| g * i).sum::<f64>() / (total * total);
    let slopes = landings
        .iter()
        .zip(photons)
        .map(|(landing, photon)| {
            let Some(st) = landing else { return [0.0; 2] };
            let (x, y) = at(st);
            let (mut dx, mut dy) = (0.0, 0.0);
            for (cx, cy) in cells(x, y) {
                let (ox, oy) = (cx as f64 - x, cy as f64 - y);
                let k = photon.weight * kernel(ox, oy) / (sigma * sigma);
                let c = g[cy as usize * nx + cx as usize] / total - shared;
                dx += c * k * ox;
                dy += c * k * oy;
            }
            // x = s·nx − ½, y = (1 − t)·ny − ½.
            [dx * nx as f64, -dy * ny as f64]
        })
        .collect();
    (loss, slopes)
}

/// The loss's gradient with respect to each parameter: the landing points' slopes through
/// their derivatives, and the smoothness term's.
fn gradient(
    landings: &[Option<[D1; 2]>],
    slopes: &[[f64; 2]],
    (params, theta): (&DesignParams, &[f64]),
    settings: &DesignSettings,
) -> Vec<f64> {
    let mut gradient = vec![0.0; params.len()];
    for (landing, slope) in landings.iter().zip(slopes) {
        if let Some([s, t]) = landing {
            for &(q, d) in &s.g {
                gradient[q as usize] += slope[0] * d;
            }
            for &(q, d) in &t.g {
                gradient[q as usize] += slope[1] * d;
            }
        }
    }
    let scale = settings.smoothness / (settings.max_height * settings.max_height);
    for &(a, b) in &params.neighbours {
        let diff = 2.0 * scale * (theta[a as usize] - theta[b as usize]);
        gradient[a as usize] += diff;
        gradient[b as usize] -= diff;
    }
    gradient
}

/// The picture the photons draw on the receiver grid (row 0 at the top), scaled to sum to 1:
/// what the loss compares with the target.
pub fn drawn(
    scene: &Scene,
    (params, receiver): (&DesignParams, &Receiver),
    photons: &[DesignPhoton],
    settings: &DesignSettings,
) -> Vec<f64> {
    let (nx, ny) = settings.grid;
    let mut image = vec![0.0; nx * ny];
    for photon in photons {
        if let Some([s, t]) = land(scene, params, receiver, photon.ray, settings.bounces) {
            let (x, y) = (s.v * nx as f64, (1.0 - t.v) * ny as f64);
            let (cx, cy) = ((x as usize).min(nx - 1), (y as usize).min(ny - 1));
            image[cy * nx + cx] += photon.weight;
        }
    }
    let total: f64 = image.iter().sum();
    if total > 0.0 {
        image.iter_mut().for_each(|v| *v /= total);
    }
    image
}

/// The loss of the surface as it is now over every photon.
fn full_loss(
    scene: &Scene,
    (params, receiver): (&DesignParams, &Receiver),
    photons: &[DesignPhoton],
    target: &[f64],
    settings: &DesignSettings,
) -> f64 {
    let landings: Vec<Option<[D1; 2]>> = photons
        .par_iter()
        .map(|p| land(scene, params, receiver, p.ray, settings.bounces))
        .collect();
    let target = blurred(target, settings.grid, settings.sigma);
    loss_and_slopes(&landings, photons, &target, (settings.grid, settings.sigma)).0
}

/// Runs the design on `scene` (its surface moved to the design's last moves when it returns),
/// calling `report` after every step with its figures and the moves so far (`θ`); the design
/// ends early when `report` breaks.
pub fn design(
    scene: &mut Scene,
    (params, receiver): (&DesignParams, &Receiver),
    photons: &[DesignPhoton],
    target: &[f64],
    settings: &DesignSettings,
    mut report: impl FnMut(&StepReport, &[f64]) -> std::ops::ControlFlow<()>,
) -> DesignOutcome {
    let started = std::time::Instant::now();
    let count = params.len();
    let mut theta = vec![0.0; count];
    let (mut m, mut v) = (vec![0.0; count], vec![0.0; count]);
    let (beta1, beta2, epsilon) = (0.9, 0.999, 1e-12);
    let initial_loss = full_loss(scene, (params, receiver), photons, target, settings);
    let subsets = settings.subsets.max(1);
    let mut steps = Vec::new();
    for step in 0..settings.max_steps {
        if !params.apply(scene, &theta) {
            break;
        }
        let subset: Vec<DesignPhoton> = photons
            .iter()
            .skip(step % subsets)
            .step_by(subsets)
            .copied()
            .collect();
        let landings: Vec<Option<[D1; 2]>> = subset
            .par_iter()
            .map(|p| land(scene, params, receiver, p.ray, settings.bounces))
            .collect();
        // By steps, not time, so that a design with the same steps is the same on any machine.
        let progress = step as f64 / settings.max_steps as f64;
        let sigma = settings.sigma * (1.0 + (BLUR_START - 1.0) * (1.0 - progress).powi(2));
        let aim = blurred(target, settings.grid, sigma);
        let (loss, slopes) = loss_and_slopes(&landings, &subset, &aim, (settings.grid, sigma));
        let landed = landings.iter().filter(|l| l.is_some()).count() as f64 / subset.len().max(1) as f64;
        let elapsed = started.elapsed().as_secs_f64();
        let figures = StepReport {
            step,
            loss,
            elapsed,
            landed,
        };
        steps.push(figures);
        if report(&figures, &theta).is_break() || elapsed >= settings.seconds {
            break;
        }
        let gradient = gradient(&landings, &slopes, (params, &theta), settings);
        let rate = settings.step * 0.5 * (1.0 + (std::f64::consts::PI * progress).cos());
        let t = (step + 1) as i32;
        for q in 0..count {
            m[q] = beta1 * m[q] + (1.0 - beta1) * gradient[q];
            v[q] = beta2 * v[q] + (1.0 - beta2) * gradient[q] * gradient[q];
            let (m_hat, v_hat) = (m[q] / (1.0 - beta1.powi(t)), v[q] / (1.0 - beta2.powi(t)));
            theta[q] = (theta[q] - rate * m_hat / (v_hat.sqrt() + epsilon))
                .clamp(-settings.max_height, settings.max_height);
        }
    }
    params.apply(scene, &theta);
    let final_loss = full_loss(scene, (params, receiver), photons, target, settings);
    DesignOutcome {
        theta,
        final_loss,
        initial_loss,
        steps,
    }
}
