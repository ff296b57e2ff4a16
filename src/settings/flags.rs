//! The command line's flags for the render settings, made from the table ([`SETTINGS`]): one
//! flag a setting (`--alpha 0.5`, `--direct-light off`, `--radius auto`), its help the table's,
//! laid over a scene's settings by [`SettingFlags::apply`], whose errors name the flag.
//! Flatten [`SettingFlags`] into a command's clap arguments to give it every setting.

use clap::{Arg, ArgAction, ArgMatches, Command};

use super::params::{find_setting, RenderParams, SETTINGS};
use super::setting::{Kind, Setting};

/// The render settings given on the command line, in the table's order, as given.
#[derive(Clone, Debug, Default)]
pub struct SettingFlags {
    given: Vec<(&'static Setting, String)>,
}

impl SettingFlags {
    /// The text given for setting `key`.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.given
            .iter()
            .find(|(s, _)| s.key == key)
            .map(|(_, v)| v.as_str())
    }

    /// Whether no setting was given.
    pub fn is_empty(&self) -> bool {
        self.given.is_empty()
    }

    /// Lays the flags given over `params` and checks the result with
    /// [`RenderParams::validate`]; the error names the flag (`--alpha must be in (0, 1], got
    /// 1.5`).
    pub fn apply(&self, params: &mut RenderParams) -> Result<(), String> {
        for (setting, text) in &self.given {
            params
                .set_text(setting.key, text)
                .map_err(|e| format!("{} {e}", setting.flag()))?;
        }
        params.validate().map_err(|e| {
            let flag = find_setting(e.field).map_or_else(|| e.field.to_owned(), Setting::flag);
            format!("{flag} {}", e.problem)
        })
    }
}

/// The flag of `setting`.
fn arg(setting: &'static Setting) -> Arg {
    let (value_name, values) = match setting.kind {
        Kind::Bool => ("on|off", String::new()),
        Kind::Int | Kind::Real => ("N", String::new()),
        Kind::Auto => ("N|auto", String::new()),
        Kind::Color => ("R,G,B", String::new()),
        Kind::Choice => {
            let names: Vec<&str> = setting.choices.iter().map(|c| c.0).collect();
            ("NAME", format!(" One of: {}.", names.join(", ")))
        }
    };
    Arg::new(setting.key)
        .long(setting.flag)
        .value_name(value_name)
        .action(ArgAction::Set)
        .allow_negative_numbers(true)
        .help(format!(
            "{} Default: the scene's, or {}.",
            setting.summary(),
            setting.default
        ))
        .long_help(format!(
            "{}{values} Default: the scene's, or {}.",
            setting.help, setting.default
        ))
        .help_heading("Render settings (as a scene's [render] table; see scenes/FORMAT.md)")
}

impl clap::FromArgMatches for SettingFlags {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        let given = SETTINGS
            .iter()
            .filter_map(|s| Some((s, matches.get_one::<String>(s.key)?.clone())))
            .collect();
        Ok(Self { given })
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(matches)?;
        Ok(())
    }
}

impl clap::Args for SettingFlags {
    fn augment_args(cmd: Command) -> Command {
        cmd.args(SETTINGS.iter().map(arg))
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Line {
        #[command(flatten)]
        settings: SettingFlags,
    }

    #[test]
    fn every_setting_has_a_flag_that_sets_it_and_names_itself_in_errors() {
        let line = Line::try_parse_from([
            "x",
            "--alpha",
            "0.5",
            "--direct-light",
            "off",
            "--radius",
            "auto",
            "--radius-schedule",
            "per-point",
            "--ambient",
            "0.1,0,0",
        ])
        .expect("parses");
        let mut p = RenderParams {
            initial_radius: Some(0.3),
            ..Default::default()
        };
        line.settings.apply(&mut p).expect("valid");
        assert_eq!((p.alpha, p.direct_light, p.initial_radius), (0.5, false, None));
        assert_eq!(p.ambient, glam::DVec3::new(0.1, 0.0, 0.0));
        let bad = Line::try_parse_from(["x", "--alpha", "1.5"]).expect("parses");
        assert_eq!(
            bad.settings.apply(&mut RenderParams::default()),
            Err("--alpha must be in (0, 1], got 1.5".into())
        );
        let bad = Line::try_parse_from(["x", "--index", "octree"]).expect("parses");
        assert_eq!(
            bad.settings.apply(&mut RenderParams::default()),
            Err("--index must be one of grid, kd, got \"octree\"".into())
        );
        // Every setting's flag is accepted.
        for s in SETTINGS {
            let value = match s.kind {
                Kind::Bool => "on",
                Kind::Choice => s.choices[0].0,
                Kind::Color => "0,0,0",
                _ => "1",
            };
            let line = Line::try_parse_from(["x", &s.flag(), value]).expect("the flag exists");
            assert_eq!(line.settings.get(s.key), Some(value));
        }
    }
}
