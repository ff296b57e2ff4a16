//! The `[render]` table of `scenes/FORMAT.md`, written from the table of settings
//! ([`super::SETTINGS`]): `tests/settings.rs` checks that the file holds exactly this, so the
//! format's documentation cannot drift from what the program reads.

use super::params::SETTINGS;
use super::setting::Setting;
use super::RendererKind;

/// The line before the table in FORMAT.md.
pub const BEGIN: &str =
    "<!-- [render] keys: written from src/settings/params.rs (tests/settings.rs checks it) -->";
/// The line after it.
pub const END: &str = "<!-- end of [render] keys -->";

/// Which renderers read a setting, in words, as the start of its meaning.
fn readers(s: &Setting) -> String {
    if s.renderers.len() == RendererKind::ALL.len() {
        return String::new();
    }
    // Labels in lower case within the sentence, but an acronym ("VCM") as it is.
    let in_sentence = |label: &str| {
        if label.chars().take(2).all(char::is_uppercase) {
            label.to_owned()
        } else {
            label.to_lowercase()
        }
    };
    let names: Vec<String> = s.renderers.iter().map(|k| in_sentence(k.label())).collect();
    let names = names.join(" and ");
    let mut first = names.chars();
    let capital: String = first
        .next()
        .map(|c| c.to_uppercase().chain(first).collect())
        .unwrap_or_default();
    format!("*{capital}.* ")
}

/// The Markdown table of every setting: key and flag, meaning, default.
pub fn markdown_table() -> String {
    let mut out = String::from("| key (flag) | meaning | default |\n|---|---|---|\n");
    for s in SETTINGS {
        let unit = if s.unit.is_empty() {
            String::new()
        } else {
            format!(" Unit: {}.", s.unit)
        };
        let live = if s.live {
            ""
        } else {
            " Changing it restarts the render."
        };
        out.push_str(&format!(
            "| `{}` (`{}`) | {}{}{unit}{live} | {} |\n",
            s.key,
            s.flag(),
            readers(s),
            s.help.replace('|', "\\|"),
            s.default.replace('|', "\\|"),
        ));
    }
    out
}
