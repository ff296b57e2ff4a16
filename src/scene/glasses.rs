//! How a glass's index of refraction varies with wavelength (dispersion): named optical
//! glasses by their Sellmeier coefficients, or any index with an Abbe number by Cauchy's
//! two-term formula fitted to it.
//!
//! The Sellmeier form `n²(λ) = 1 + Σᵢ Bᵢ λ² / (λ² − Cᵢ)` (λ in µm) with the coefficients of the
//! manufacturers' catalogues: Schott's for N-BK7, F2 and SF11, and Malitson 1965,
//! "Interspecimen comparison of the refractive index of fused silica", for fused silica (the
//! same data as pbrt-v4's named spectra `glass-BK7`, `glass-F2`, `glass-SF11` and
//! `glass-fused-silica`). Cauchy's `n(λ) = A + B / λ²` is fitted so that `n(λd) = ior` and
//! `(n(λd) − 1) / (n(λF) − n(λC))` is the Abbe number `V`, at the Fraunhofer lines d, F and C.

/// The helium d line, 587.56 nm: where a glass's nominal index `n_d` is given.
pub const D_LINE_NM: f64 = 587.56;
/// The hydrogen F line, 486.13 nm.
const F_LINE_NM: f64 = 486.13;
/// The hydrogen C line, 656.27 nm.
const C_LINE_NM: f64 = 656.27;

/// A named glass: its names in a scene file and its Sellmeier coefficients (λ in µm).
pub struct NamedGlass {
    /// The names a scene may call it by, compared without case (the first is listed in
    /// messages).
    pub names: &'static [&'static str],
    /// `B₁, B₂, B₃`.
    pub b: [f64; 3],
    /// `C₁, C₂, C₃` in µm².
    pub c: [f64; 3],
}

/// The glasses a scene may name.
pub const GLASSES: &[NamedGlass] = &[
    NamedGlass {
        names: &["BK7", "N-BK7"],
        b: [1.039_612_12, 0.231_792_344, 1.010_469_45],
        c: [0.006_000_698_67, 0.020_017_914_4, 103.560_653],
    },
    NamedGlass {
        names: &["F2"],
        b: [1.345_333_59, 0.209_073_176, 0.937_357_162],
        c: [0.009_977_438_71, 0.047_045_076_7, 111.886_764],
    },
    NamedGlass {
        names: &["SF11"],
        b: [1.737_596_95, 0.313_747_346, 1.898_781_01],
        c: [0.013_188_707, 0.062_306_814_2, 155.236_29],
    },
    NamedGlass {
        names: &["fused silica", "fused-silica", "silica"],
        b: [0.696_166_3, 0.407_942_6, 0.897_479_4],
        c: [0.004_679_148_26, 0.013_512_063_1, 97.934_002_5],
    },
];

/// How a glass's index depends on the wavelength.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Dispersion {
    /// The same index at every wavelength.
    None,
    /// Cauchy's `n(λ) = a + b / λ²`, λ in µm.
    Cauchy {
        /// `A`.
        a: f64,
        /// `B` in µm².
        b: f64,
    },
    /// Sellmeier's `n²(λ) = 1 + Σᵢ Bᵢ λ² / (λ² − Cᵢ)`, λ in µm.
    Sellmeier {
        /// `B₁, B₂, B₃`.
        b: [f64; 3],
        /// `C₁, C₂, C₃` in µm².
        c: [f64; 3],
    },
}

impl Dispersion {
    /// The named glass `name` (any case), `None` if there is no such glass.
    pub fn named(name: &str) -> Option<Self> {
        GLASSES
            .iter()
            .find(|g| g.names.iter().any(|n| n.eq_ignore_ascii_case(name)))
            .map(|g| Dispersion::Sellmeier { b: g.b, c: g.c })
    }

    /// Cauchy's formula through `n(λd) = ior` with Abbe number `abbe` (> 0).
    pub fn abbe(ior: f64, abbe: f64) -> Self {
        let inv2 = |nm: f64| 1.0 / (nm * 1e-3 * nm * 1e-3);
        let b = (ior - 1.0) / (abbe * (inv2(F_LINE_NM) - inv2(C_LINE_NM)));
        Dispersion::Cauchy {
            a: ior - b * inv2(D_LINE_NM),
            b,
        }
    }

    /// Whether the index varies with the wavelength.
    pub fn is_dispersive(&self) -> bool {
        !matches!(self, Dispersion::None)
    }

    /// The index at `nm` nanometres, or `nominal` where there is no dispersion.
    pub fn ior(&self, nominal: f64, nm: f64) -> f64 {
        let um2 = (nm * 1e-3) * (nm * 1e-3);
        match *self {
            Dispersion::None => nominal,
            Dispersion::Cauchy { a, b } => a + b / um2,
            Dispersion::Sellmeier { b, c } => {
                let sum: f64 = (0..3).map(|i| b[i] * um2 / (um2 - c[i])).sum();
                (1.0 + sum).sqrt()
            }
        }
    }

    /// The Abbe number `(n_d − 1) / (n_F − n_C)` (infinite without dispersion).
    pub fn abbe_number(&self, nominal: f64) -> f64 {
        let n = |nm| self.ior(nominal, nm);
        (n(D_LINE_NM) - 1.0) / (n(F_LINE_NM) - n(C_LINE_NM))
    }
}

/// The names listed in messages: "BK7, F2, SF11, fused silica".
pub fn names() -> String {
    GLASSES.iter().map(|g| g.names[0]).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The catalogue's `n_d` and `V_d` of each named glass (Schott's data sheets; fused silica
    /// from Malitson's paper).
    #[test]
    fn named_glasses_match_their_catalogue_values() {
        for (name, n_d, v_d) in [
            ("BK7", 1.5168, 64.17),
            ("F2", 1.6200, 36.37),
            ("SF11", 1.78472, 25.68),
            ("fused silica", 1.4585, 67.8),
        ] {
            let g = Dispersion::named(name).expect("a named glass");
            let n = g.ior(0.0, D_LINE_NM);
            assert!((n - n_d).abs() < 2e-4, "{name}: n_d {n}, catalogue {n_d}");
            let v = g.abbe_number(0.0);
            assert!((v - v_d).abs() < 0.3, "{name}: V_d {v}, catalogue {v_d}");
        }
        assert!(Dispersion::named("bk7").is_some());
        assert!(Dispersion::named("unobtainium").is_none());
    }

    #[test]
    fn cauchy_fit_has_the_asked_index_and_abbe_number() {
        let d = Dispersion::abbe(1.6, 30.0);
        assert!((d.ior(0.0, D_LINE_NM) - 1.6).abs() < 1e-12);
        assert!((d.abbe_number(0.0) - 30.0).abs() < 1e-9);
        // Normal dispersion: blue bends more than red.
        assert!(d.ior(0.0, 450.0) > d.ior(0.0, 650.0));
        assert_eq!(Dispersion::None.ior(1.5, 450.0), 1.5);
    }
}
