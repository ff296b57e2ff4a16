//! What the table of render settings (`settings/params.rs`, [`super::SETTINGS`]) says of each setting ([`Setting`]),
//! and the typed values behind it ([`Field`], [`Value`]): enough for the scene loader, the
//! command line's flags ([`super::flags`]), the viewer's widgets and the benches to handle
//! every setting the same way, by its key, without naming it.

use glam::DVec3;

use super::{IndexKind, RadiusSchedule, RendererKind};

/// One render setting: its `[render]` key and everything the program says or checks of it.
#[derive(Clone, Copy, Debug)]
pub struct Setting {
    /// The key in a scene's `[render]` table (and the field of `RenderParams`).
    pub key: &'static str,
    /// The command line's flag, without its dashes.
    pub flag: &'static str,
    /// The viewer's label.
    pub label: &'static str,
    /// What it does: FORMAT.md's text, the flag's long help, the widget's tooltip.
    pub help: &'static str,
    /// The default, as a scene file would write it (or in words).
    pub default: &'static str,
    /// Its unit, or "".
    pub unit: &'static str,
    /// The renderers that read it.
    pub renderers: &'static [RendererKind],
    /// Whether a change applies from the next pass, keeping the image so far (else it restarts).
    pub live: bool,
    /// How the viewer shows it.
    pub widget: Widget,
    /// The values a choice takes: name (as files and flags write it), label and tooltip.
    pub choices: &'static [(&'static str, &'static str, &'static str)],
    /// The shape of its values.
    pub kind: Kind,
}

impl Setting {
    /// Whether `kind` reads it.
    pub fn used_by(&self, kind: RendererKind) -> bool {
        self.renderers.contains(&kind)
    }

    /// The help's first sentence: the flag's short help.
    pub fn summary(&self) -> &'static str {
        match self.help.find(". ") {
            Some(end) => &self.help[..end + 1],
            None => self.help,
        }
    }

    /// The command line's flag, with its dashes.
    pub fn flag(&self) -> String {
        format!("--{}", self.flag)
    }
}

/// The shape of a setting's values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// On or off.
    Bool,
    /// A whole number.
    Int,
    /// A real number.
    Real,
    /// A real number, or automatic.
    Auto,
    /// An RGB triple.
    Color,
    /// One of [`Setting::choices`].
    Choice,
}

/// How the viewer shows a setting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Widget {
    /// Not in the side panel (the renderer's buttons show it, or it is left to files and flags).
    Hidden,
    /// A checkbox.
    Checkbox,
    /// A slider over `min..=max` (logarithmic when `log`), in steps of `step` (0: any).
    Slider {
        /// Lowest value.
        min: f64,
        /// Highest value.
        max: f64,
        /// A logarithmic slider.
        log: bool,
        /// Step (0: any).
        step: f64,
    },
    /// A checkbox `automatic` and, off, a slider over `min..=max`; lengths (`scene_length`)
    /// scale with the scene's size, `min` and `max` then being fractions of its extent.
    Auto {
        /// The checkbox's label.
        automatic: &'static str,
        /// Lowest value.
        min: f64,
        /// Highest value.
        max: f64,
        /// Whether the range is a fraction of the scene's extent.
        scene_length: bool,
        /// The slider's value before the user sets one, when not a scene length.
        manual: f64,
    },
    /// A button for each choice.
    Choice,
}

/// A setting's value, whatever its type.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// [`Kind::Bool`].
    Bool(bool),
    /// [`Kind::Int`].
    Int(u64),
    /// [`Kind::Real`].
    Real(f64),
    /// [`Kind::Auto`]: `None` is automatic.
    Auto(Option<f64>),
    /// [`Kind::Color`].
    Color(DVec3),
    /// [`Kind::Choice`]: the choice's name.
    Choice(&'static str),
}

impl Value {
    /// As a scene file or a flag writes it.
    pub fn text(&self) -> String {
        match self {
            Value::Bool(b) => if *b { "on" } else { "off" }.into(),
            Value::Int(n) => n.to_string(),
            Value::Real(x) => x.to_string(),
            Value::Auto(None) => "auto".into(),
            Value::Auto(Some(x)) => x.to_string(),
            Value::Color(c) => format!("{},{},{}", c.x, c.y, c.z),
            Value::Choice(name) => (*name).into(),
        }
    }
}

/// A type a setting holds: how it reads from text (flags, bench configurations), and how it
/// converts to and from a [`Value`].
pub trait Field: Sized {
    /// The shape of its values.
    const KIND: Kind;
    /// Its value read from `text`; the error ends a message ("must be …, got …").
    fn parse(text: &str) -> Result<Self, String>;
    /// As a [`Value`].
    fn value(&self) -> Value;
    /// From a [`Value`] of its kind.
    fn from_value(value: &Value) -> Option<Self>;
    /// The values a choice takes (name, label, tooltip).
    const CHOICES: &'static [(&'static str, &'static str, &'static str)] = &[];
}

impl Field for bool {
    const KIND: Kind = Kind::Bool;
    fn parse(text: &str) -> Result<Self, String> {
        match text.to_ascii_lowercase().as_str() {
            "on" | "true" | "yes" | "1" => Ok(true),
            "off" | "false" | "no" | "0" => Ok(false),
            _ => Err(format!("must be on or off, got {text:?}")),
        }
    }
    fn value(&self) -> Value {
        Value::Bool(*self)
    }
    fn from_value(value: &Value) -> Option<Self> {
        match value {
            Value::Bool(b) => Some(*b),
            _ => None,
        }
    }
}

/// Whole numbers of any width.
macro_rules! int_field {
    ($($t:ty),*) => {$(
        impl Field for $t {
            const KIND: Kind = Kind::Int;
            fn parse(text: &str) -> Result<Self, String> {
                text.trim().parse().map_err(|_| format!("must be a whole number, got {text:?}"))
            }
            fn value(&self) -> Value {
                Value::Int(*self as u64)
            }
            fn from_value(value: &Value) -> Option<Self> {
                match value {
                    Value::Int(n) => <$t>::try_from(*n).ok(),
                    Value::Real(x) if x.fract() == 0.0 && *x >= 0.0 => <$t>::try_from(*x as u64).ok(),
                    _ => None,
                }
            }
        }
    )*};
}
int_field!(u32, u64);

/// A real number from text: finite, or the error.
fn real(text: &str) -> Result<f64, String> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| format!("must be a finite number, got {text:?}"))
}

impl Field for f64 {
    const KIND: Kind = Kind::Real;
    fn parse(text: &str) -> Result<Self, String> {
        real(text)
    }
    fn value(&self) -> Value {
        Value::Real(*self)
    }
    fn from_value(value: &Value) -> Option<Self> {
        match value {
            Value::Real(x) => Some(*x),
            Value::Int(n) => Some(*n as f64),
            _ => None,
        }
    }
}

impl Field for Option<f64> {
    const KIND: Kind = Kind::Auto;
    fn parse(text: &str) -> Result<Self, String> {
        if text.trim().eq_ignore_ascii_case("auto") {
            Ok(None)
        } else {
            real(text)
                .map(Some)
                .map_err(|_| format!("must be a finite number or auto, got {text:?}"))
        }
    }
    fn value(&self) -> Value {
        Value::Auto(*self)
    }
    fn from_value(value: &Value) -> Option<Self> {
        match value {
            Value::Auto(x) => Some(*x),
            Value::Real(x) => Some(Some(*x)),
            _ => None,
        }
    }
}

impl Field for DVec3 {
    const KIND: Kind = Kind::Color;
    fn parse(text: &str) -> Result<Self, String> {
        let parts: Vec<&str> = text.split(',').collect();
        let [r, g, b] = parts.as_slice() else {
            return Err(format!("must be three numbers 'r,g,b', got {text:?}"));
        };
        Ok(DVec3::new(real(r)?, real(g)?, real(b)?))
    }
    fn value(&self) -> Value {
        Value::Color(*self)
    }
    fn from_value(value: &Value) -> Option<Self> {
        match value {
            Value::Color(c) => Some(*c),
            _ => None,
        }
    }
}

/// A choice among a closed set of values, each with a name, a label and a tooltip.
macro_rules! choice_field {
    ($t:ty, [$($variant:expr, $name:literal, $label:literal, $help:literal;)*]) => {
        impl Field for $t {
            const KIND: Kind = Kind::Choice;
            fn parse(text: &str) -> Result<Self, String> {
                let wanted = text.trim().replace('-', "_");
                $(if wanted == $name.replace('-', "_") {
                    return Ok($variant);
                })*
                Err(format!("must be one of {}, got {text:?}", [$($name),*].join(", ")))
            }
            fn value(&self) -> Value {
                $(if *self == $variant {
                    return Value::Choice($name);
                })*
                unreachable!("every variant is listed")
            }
            fn from_value(value: &Value) -> Option<Self> {
                match value {
                    Value::Choice(name) => Self::parse(name).ok(),
                    _ => None,
                }
            }
            const CHOICES: &'static [(&'static str, &'static str, &'static str)] =
                &[$(($name, $label, $help)),*];
        }
    };
}

choice_field!(IndexKind, [
    IndexKind::HashGrid, "grid", "Hash grid", "Hashed uniform grid (fastest here)";
    IndexKind::KdTree, "kd", "kd-tree", "The seed report's kd-tree";
]);

choice_field!(RadiusSchedule, [
    RadiusSchedule::PerPoint, "per_point", "Per point", "Each point's photon count and flux carry from pass to pass and its radius shrinks with the photons it gathered (Hachisuka et al. 2008)";
    RadiusSchedule::Global, "global", "Global schedule", "Every pass is an independent estimate at one shrinking radius (Knaus & Zwicker 2011): the passes of a render can be split across machines and merged (render --shard, caustic merge). α and the radii are fixed by a pilot pass; changing α restarts";
]);

impl Field for RendererKind {
    const KIND: Kind = Kind::Choice;
    fn parse(text: &str) -> Result<Self, String> {
        RendererKind::from_name(text.trim()).ok_or_else(|| {
            let names: Vec<&str> = RendererKind::ALL.iter().map(|k| k.name()).collect();
            format!("must be one of {}, got {text:?}", names.join(", "))
        })
    }
    fn value(&self) -> Value {
        Value::Choice(self.name())
    }
    fn from_value(value: &Value) -> Option<Self> {
        match value {
            Value::Choice(name) => RendererKind::from_name(name),
            _ => None,
        }
    }
    const CHOICES: &'static [(&'static str, &'static str, &'static str)] = RendererKind::CHOICES;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_read_what_they_write() {
        assert_eq!(bool::parse("off"), Ok(false));
        assert!(bool::parse("maybe").is_err());
        assert_eq!(<Option<f64>>::parse("auto"), Ok(None));
        assert_eq!(<Option<f64>>::parse("0.5"), Ok(Some(0.5)));
        assert!(f64::parse("nan").is_err());
        assert_eq!(RadiusSchedule::parse("per-point"), Ok(RadiusSchedule::PerPoint));
        assert_eq!(RadiusSchedule::Global.value(), Value::Choice("global"));
        assert_eq!(DVec3::parse("1,2,3"), Ok(DVec3::new(1.0, 2.0, 3.0)));
        for v in [
            Value::Bool(true),
            Value::Int(3),
            Value::Real(0.5),
            Value::Auto(None),
            Value::Choice("kd"),
        ] {
            let text = v.text();
            let back = match v {
                Value::Bool(_) => bool::parse(&text).map(|b| b.value()),
                Value::Int(_) => u64::parse(&text).map(|n| n.value()),
                Value::Real(_) => f64::parse(&text).map(|x| x.value()),
                Value::Auto(_) => <Option<f64>>::parse(&text).map(|x| x.value()),
                _ => IndexKind::parse(&text).map(|c| c.value()),
            };
            assert_eq!(back, Ok(v));
        }
    }
}
