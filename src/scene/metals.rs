//! Named metals for the `metal` material: each one's complex index of refraction `η + ik` at
//! the wavelengths that stand for the red, green and blue channels (650, 550 and 440 nm), from
//! measured optical constants as tabulated at refractiveindex.info (Johnson & Christy 1972,
//! "Optical constants of the noble metals", for gold, silver and copper; Rakić 1995 for
//! aluminium), in the RGB form many renderers use.

use glam::DVec3;

/// A named metal: its names in a scene file, and `(η, k)` per channel.
pub struct NamedMetal {
    /// The names a scene may call it by (the first is the one listed in messages).
    pub names: &'static [&'static str],
    /// The real part of the index.
    pub eta: [f64; 3],
    /// The extinction coefficient.
    pub k: [f64; 3],
}

/// The metals a scene may name.
pub const METALS: &[NamedMetal] = &[
    NamedMetal {
        names: &["gold"],
        eta: [0.18299, 0.42108, 1.37340],
        k: [3.42420, 2.34590, 1.77040],
    },
    NamedMetal {
        names: &["silver"],
        eta: [0.15943, 0.14512, 0.13547],
        k: [3.92910, 3.19000, 2.38080],
    },
    NamedMetal {
        names: &["copper"],
        eta: [0.27105, 0.67693, 1.31640],
        k: [3.60920, 2.62480, 2.29210],
    },
    NamedMetal {
        names: &["aluminium", "aluminum"],
        eta: [1.34560, 0.96521, 0.61722],
        k: [7.47460, 6.39950, 5.30310],
    },
];

/// `(η, k)` of the metal called `name`.
pub fn named(name: &str) -> Option<(DVec3, DVec3)> {
    METALS
        .iter()
        .find(|m| m.names.contains(&name))
        .map(|m| (DVec3::from_array(m.eta), DVec3::from_array(m.k)))
}

/// The names listed in messages: "gold, silver, copper, aluminium".
pub fn names() -> String {
    METALS.iter().map(|m| m.names[0]).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At normal incidence, `((η − 1)² + k²) / ((η + 1)² + k²)`: gold and copper reflect red
    /// most and blue least, silver and aluminium are nearly grey and bright, as their colours
    /// are (gold about (0.94, 0.78, 0.37)).
    #[test]
    fn named_metals_have_their_colours() {
        let r0 = |name: &str| {
            let (eta, k) = named(name).expect("named");
            let k2 = k * k;
            ((eta - 1.0) * (eta - 1.0) + k2) / ((eta + 1.0) * (eta + 1.0) + k2)
        };
        let gold = r0("gold");
        assert!(
            (gold - DVec3::new(0.94, 0.78, 0.37)).abs().max_element() < 0.02,
            "{gold}"
        );
        let copper = r0("copper");
        assert!(copper.x > copper.y && copper.y > copper.z, "{copper}");
        for grey in ["silver", "aluminium", "aluminum"] {
            let r = r0(grey);
            assert!(
                r.min_element() > 0.85 && r.max_element() - r.min_element() < 0.1,
                "{grey}: {r}"
            );
        }
        assert_eq!(named("brass"), None);
        assert_eq!(names(), "gold, silver, copper, aluminium");
    }
}
