//! Which renderer makes the image ([`RendererKind`]): made from the one list of renderers
//! ([`with_renderers`], here, in the lowest layer), so the scene format, the command line
//! (`--renderer`), the viewer's buttons and the render layer's integrators all come from it.

use serde::{Deserialize, Serialize};

/// Makes [`RendererKind`] from the list (the integrator column is the render layer's).
macro_rules! renderers {
    ($($variant:ident, $name:literal, $label:literal, $about:literal, $mode:ident, $module:ident :: $integrator:ident;)*) => {
        /// Which renderer makes the image: `renderer = "NAME"` in a scene's `[render]` table,
        /// `--renderer NAME` on the command line, a button in the viewer.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
        pub enum RendererKind {
            $(
                #[doc = $label]
                #[value(name = $name)]
                $variant,
            )*
        }

        impl RendererKind {
            /// Every renderer, in the list's order.
            pub const ALL: &'static [RendererKind] = &[$(RendererKind::$variant),*];

            /// Every renderer's name, label and description, in the list's order.
            pub const CHOICES: &'static [(&'static str, &'static str, &'static str)] =
                &[$(($name, $label, $about)),*];

            /// The name in scene files and on the command line.
            pub fn name(self) -> &'static str {
                match self {
                    $(RendererKind::$variant => $name,)*
                }
            }

            /// The label the viewer shows.
            pub fn label(self) -> &'static str {
                match self {
                    $(RendererKind::$variant => $label,)*
                }
            }

            /// What it does, in a sentence (the viewer's tooltip).
            pub fn description(self) -> &'static str {
                match self {
                    $(RendererKind::$variant => $about,)*
                }
            }

            /// Whether it renders pass after pass until stopped (else one frame per epoch).
            pub fn progressive(self) -> bool {
                match self {
                    $(RendererKind::$variant => renderers!(@progressive $mode),)*
                }
            }
        }
    };
    (@progressive progressive) => { true };
    (@progressive single) => { false };
}

/// The renderers, one line each: the variant of [`RendererKind`], its name in scene files and
/// on the command line, its label and tooltip in the viewer, whether it renders passes
/// without end (`progressive`) or one frame per epoch (`single`), and its integrator: a file in
/// `src/render/integrator/` and the type there that implements `Integrator`.
///
/// The list is handed to the macro `$callback`: this module makes `RendererKind` from its
/// first five columns, and `render::integrator` declares the modules and makes each kind's
/// integrator. A new renderer is its file there plus one line here.
macro_rules! with_renderers {
    ($callback:ident) => {
        $callback! {
            Whitted, "whitted", "Ray tracer", "Whitted ray tracer: one fast frame, direct light, mirrors and glass only", single, ray_tracer::RayTracer;
            Ppm, "ppm", "Photon mapping", "Progressive photon mapping: converges to caustics and indirect light", progressive, photon_mapping::PhotonMapping;
            Path, "path", "Path tracer", "Unidirectional path tracer with light sampling and MIS: an unbiased cross-check of photon mapping", progressive, path::PathTracer;
            Vcm, "vcm", "VCM", "Vertex connection and merging: path tracing, light tracing and photon mapping combined by multiple importance sampling", progressive, vcm::Vcm;
        }
    };
}
pub(crate) use with_renderers;

with_renderers!(renderers);

impl RendererKind {
    /// The kind named `name`.
    pub fn from_name(name: &str) -> Option<RendererKind> {
        Self::ALL.iter().copied().find(|k| k.name() == name)
    }

    /// What a pass's sample count counts, in words: VCM's light subpaths play photon
    /// mapping's photons (a frame's and a part's `photons`).
    pub fn emitted(self) -> &'static str {
        match self {
            RendererKind::Vcm => "light subpaths",
            _ => "photons",
        }
    }
}

impl Serialize for RendererKind {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for RendererKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        RendererKind::from_name(&name).ok_or_else(|| {
            let names: Vec<String> = Self::ALL.iter().map(|k| format!("\"{}\"", k.name())).collect();
            serde::de::Error::custom(format!(
                "'renderer' must be {}, got \"{name}\"",
                names.join(" or ")
            ))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_ones_list_the_known() {
        for &k in RendererKind::ALL {
            assert_eq!(RendererKind::from_name(k.name()), Some(k));
            let text = toml::to_string(&std::collections::BTreeMap::from([("r", k)])).expect("serializes");
            assert_eq!(text.trim(), format!("r = \"{}\"", k.name()));
        }
        let err = toml::from_str::<std::collections::BTreeMap<String, RendererKind>>("r = \"x\"")
            .expect_err("unknown");
        assert!(
            err.to_string()
                .contains("'renderer' must be \"whitted\" or \"ppm\""),
            "{err}"
        );
    }
}
