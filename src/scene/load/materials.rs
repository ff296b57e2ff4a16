//! `[materials.NAME]` tables and their textures.

use glam::{DVec2, DVec3};
use toml::Spanned;

use super::diagnostics::{v3, Ctx, Result, Table};
use crate::scene::format::{MaterialDesc, ScaleDesc, TextureDesc};
use crate::scene::glasses::{self, Dispersion};
use crate::scene::material::{Material, MaterialKind};
use crate::scene::metals;
use crate::scene::texture::{Mapping, Texture, TextureSource};
use crate::settings::limits;

pub(super) fn material(
    ctx: &Ctx,
    name: &str,
    desc: &Spanned<MaterialDesc>,
    textures: &mut Vec<Texture>,
) -> Result<Material> {
    let d = desc.get_ref();
    let t = Table {
        ctx,
        span: desc.span(),
        name: format!("[materials.{name}] ({})", d.kind),
    };
    let color = d
        .color
        .as_ref()
        .map(v3)
        .map(|c| t.reflectance("color", c))
        .transpose()?;
    let kind = kind(&t, d)?;
    let texture = match &d.texture {
        Some(desc) => {
            textures.push(texture(&t, desc)?);
            Some(textures.len() - 1)
        }
        None => None,
    };
    // A metal's colour tints its own reflectance: white unless given.
    let default_color = if matches!(kind, MaterialKind::Metal { .. }) {
        DVec3::ONE
    } else {
        DVec3::splat(0.75)
    };
    Ok(Material {
        name: name.to_owned(),
        kind,
        color: color.unwrap_or(default_color),
        texture,
    })
}

/// The model a `[materials.NAME]` table's `type` and keys describe, each key checked (and
/// refused where the type does not take it).
fn kind(t: &Table, d: &MaterialDesc) -> Result<MaterialKind> {
    let given = [
        ("color", d.color.is_some()),
        ("texture", d.texture.is_some()),
        ("specular", d.specular.is_some()),
        ("shininess", d.shininess.is_some()),
        ("ior", d.ior.is_some()),
        ("roughness", d.roughness.is_some()),
        ("conductor", d.conductor.is_some()),
        ("eta", d.eta.is_some()),
        ("k", d.k.is_some()),
        ("glass", d.glass.is_some()),
        ("abbe", d.abbe.is_some()),
    ];
    let roughness = || -> Result<f64> {
        let r = d.roughness.map_or(0.0, |r| r.0);
        limits::roughness(r)
            .map_err(|_| t.err(format!("'roughness' (GGX α) must be between 0 and 1, got {r}")))
    };
    let kind = match d.kind.as_str() {
        "diffuse" => {
            t.only("diffuse", &given, &["color", "texture"])?;
            MaterialKind::Diffuse {
                specular: 0.0,
                shininess: 0.0,
            }
        }
        "phong" => {
            t.only("phong", &given, &["color", "texture", "specular", "shininess"])?;
            let specular = d.specular.map_or(0.2, |r| r.0);
            if !(0.0..=1.0).contains(&specular) {
                return Err(t.err(format!("'specular' must be between 0 and 1, got {specular}")));
            }
            MaterialKind::Diffuse {
                specular,
                shininess: t.non_negative("shininess", d.shininess.map_or(32.0, |r| r.0))?,
            }
        }
        "mirror" => {
            t.only("mirror", &given, &["color", "roughness"])?;
            MaterialKind::Mirror {
                roughness: roughness()?,
            }
        }
        "metal" => {
            t.only("metal", &given, &["color", "roughness", "conductor", "eta", "k"])?;
            let (eta, k) = metal(t, d)?;
            MaterialKind::Metal {
                eta,
                k,
                roughness: roughness()?,
            }
        }
        "glass" => {
            t.only("glass", &given, &["color", "ior", "roughness", "glass", "abbe"])?;
            let (ior, dispersion) = glass(t, d)?;
            MaterialKind::Glass {
                ior,
                roughness: roughness()?,
                dispersion,
            }
        }
        other => {
            return Err(t.err(format!(
                "unknown material type '{other}' (expected diffuse, phong, mirror, metal or glass)"
            )))
        }
    };
    Ok(kind)
}

/// A glass's nominal index and its dispersion: a named `glass` (its own index), or `ior`
/// (default 1.5) with an optional Abbe number `abbe` (at least 1).
fn glass(t: &Table, d: &MaterialDesc) -> Result<(f64, Dispersion)> {
    if let Some(name) = &d.glass {
        if d.ior.is_some() || d.abbe.is_some() {
            return Err(t.err(format!(
                "'glass = \"{name}\"' gives the index itself: leave out 'ior' and 'abbe'"
            )));
        }
        let dispersion = Dispersion::named(name)
            .ok_or_else(|| t.err(format!("unknown glass '{name}' (expected {})", glasses::names())))?;
        return Ok((dispersion.ior(0.0, glasses::D_LINE_NM), dispersion));
    }
    let ior = t.positive("ior", d.ior.map_or(1.5, |r| r.0))?;
    let Some(abbe) = d.abbe.map(|r| r.0) else {
        return Ok((ior, Dispersion::None));
    };
    if !(1.0..=1000.0).contains(&abbe) {
        return Err(t.err(format!("'abbe' must be between 1 and 1000, got {abbe}")));
    }
    let dispersion = Dispersion::abbe(ior, abbe);
    // Cauchy's curve for an index below 1 falls with the wavelength and may reach 0.
    let lowest = [360.0, 830.0].map(|nm| dispersion.ior(ior, nm));
    if lowest.iter().any(|&n| n <= 0.01) {
        return Err(t.err(format!(
            "'abbe' {abbe} with 'ior' {ior} gives an index of {:.3} at the spectrum's end",
            lowest[0].min(lowest[1])
        )));
    }
    Ok((ior, dispersion))
}

/// A metal's `(η, k)`: a named `conductor`, or `eta` and `k` both given (each channel finite,
/// η positive, k not negative, both at most 100).
fn metal(t: &Table, d: &MaterialDesc) -> Result<(DVec3, DVec3)> {
    match (&d.conductor, &d.eta, &d.k) {
        (Some(name), None, None) => metals::named(name).ok_or_else(|| {
            t.err(format!(
                "unknown conductor '{name}' (expected {}, or 'eta' and 'k')",
                metals::names()
            ))
        }),
        (None, Some(eta), Some(k)) => {
            let (eta, k) = (v3(eta), v3(k));
            if !(eta.cmpgt(DVec3::ZERO).all() && eta.cmple(DVec3::splat(100.0)).all()) {
                return Err(t.err(format!(
                    "'eta' components must be above 0 and at most 100, got {eta}"
                )));
            }
            if !(k.cmpge(DVec3::ZERO).all() && k.cmple(DVec3::splat(100.0)).all()) {
                return Err(t.err(format!("'k' components must be between 0 and 100, got {k}")));
            }
            Ok((eta, k))
        }
        _ => Err(t.err(format!(
            "give either 'conductor' ({}) or both 'eta' and 'k'",
            metals::names()
        ))),
    }
}

pub(super) fn texture(t: &Table, d: &TextureDesc) -> Result<Texture> {
    let source = match (&d.file, &d.checker) {
        (Some(file), None) => {
            let path = t
                .ctx
                .resolve(&t.span, &format!("{}: 'texture.file'", t.name), file)?;
            TextureSource::load(&path).map_err(|e| t.err(format!("'texture.file': {e}")))?
        }
        (None, Some([a, b])) => TextureSource::Checker([
            t.reflectance("texture.checker", v3(a))?,
            t.reflectance("texture.checker", v3(b))?,
        ]),
        _ => return Err(t.err("'texture' needs exactly one of 'file' or 'checker'")),
    };
    let mapping = match d.mapping.as_deref() {
        None | Some("uv") => Mapping::Uv,
        Some("planar") => {
            let n = t
                .nonzero("texture.normal", d.normal.as_ref().map(v3).unwrap_or(DVec3::Z))?
                .normalize();
            let (axis_u, axis_v) = n.any_orthonormal_pair();
            Mapping::Planar { axis_u, axis_v }
        }
        Some("spherical") => Mapping::Spherical {
            center: d.center.as_ref().map(v3).unwrap_or(DVec3::ZERO),
        },
        Some(other) => {
            return Err(t.err(format!(
                "'texture.mapping' must be \"uv\", \"planar\" or \"spherical\", got \"{other}\""
            )))
        }
    };
    let scale = match d.scale {
        None => DVec2::ONE,
        Some(ScaleDesc::Uniform(s)) => DVec2::splat(s.0),
        Some(ScaleDesc::PerAxis2([a, b])) => DVec2::new(a.0, b.0),
        Some(ScaleDesc::PerAxis3(_)) => return Err(t.err("'texture.scale' takes one or two numbers")),
    };
    if scale.x == 0.0 || scale.y == 0.0 {
        return Err(t.err("'texture.scale' must not be zero"));
    }
    Ok(Texture {
        source,
        mapping,
        scale,
        offset: d.offset.map_or(DVec2::ZERO, |[a, b]| DVec2::new(a.0, b.0)),
    })
}
