//! A render setting's control in the side panel, drawn from the table of settings
//! ([`SETTINGS`]) by its widget: a checkbox, a slider, a checkbox "automatic" over a slider,
//! or a button per choice, with the table's help as its tooltip. The panel's sections pick
//! settings by the renderers that read them; no control names a setting.

use egui::Ui;

use super::params::{PanelParams, Ranges};
use crate::settings::setting::{Setting, Value, Widget};
use crate::settings::{RendererKind, SETTINGS};

/// The controls of every setting `wanted` picks, in the table's order, enabled when the
/// current renderer reads the setting.
pub fn settings_ui(p: &mut PanelParams, ranges: Ranges, ui: &mut Ui, wanted: impl Fn(&Setting) -> bool) {
    for s in SETTINGS
        .iter()
        .filter(|s| s.widget != Widget::Hidden && wanted(s))
    {
        let enabled = s.used_by(p.render.renderer);
        ui.add_enabled_ui(enabled, |ui| setting_ui(p, s, ranges, ui));
    }
}

/// Whether a setting is read by `kind` and not by every renderer: what the current
/// renderer's own section shows (the merging radius's α under both photon mapping and VCM).
pub fn read_by(kind: RendererKind) -> impl Fn(&Setting) -> bool {
    move |s| s.renderers.contains(&kind) && !every_renderer(s)
}

/// Whether a setting is read by every renderer (the depth of paths, the seed).
pub fn every_renderer(s: &Setting) -> bool {
    RendererKind::ALL.iter().all(|k| s.renderers.contains(k))
}

/// The tooltip: the table's help, and whether a change restarts the render.
fn tooltip(s: &Setting) -> String {
    if s.live {
        s.help.to_owned()
    } else {
        format!("{} Changing it restarts.", s.help)
    }
}

/// A slider over `range` (logarithmic, stepped by `step` when positive) labelled `label`;
/// whether it moved.
fn slider_ui<N: egui::emath::Numeric>(
    ui: &mut Ui,
    value: &mut N,
    range: std::ops::RangeInclusive<N>,
    (log, step): (bool, f64),
    label: &str,
    tip: &str,
) -> bool {
    let slider = egui::Slider::new(value, range).logarithmic(log).text(label);
    let slider = if step > 0.0 { slider.step_by(step) } else { slider };
    ui.add(slider).on_hover_text(tip).changed()
}

/// One setting's control.
fn setting_ui(p: &mut PanelParams, s: &'static Setting, ranges: Ranges, ui: &mut Ui) {
    let Some(value) = p.render.get(s.key) else {
        return;
    };
    let tip = tooltip(s);
    let new = match (s.widget, value) {
        (Widget::Checkbox, Value::Bool(mut on)) => ui
            .checkbox(&mut on, s.label)
            .on_hover_text(tip)
            .changed()
            .then_some(Value::Bool(on)),
        (Widget::Slider { min, max, log, step }, Value::Int(mut n)) => {
            let range = min as u64..=max as u64;
            slider_ui(ui, &mut n, range, (log, step), s.label, &tip).then_some(Value::Int(n))
        }
        (Widget::Slider { min, max, log, step }, Value::Real(mut x)) => {
            slider_ui(ui, &mut x, min..=max, (log, step), s.label, &tip).then_some(Value::Real(x))
        }
        (widget @ Widget::Auto { .. }, Value::Auto(current)) => auto_ui(p, s, widget, current, ranges, ui),
        (Widget::Choice, Value::Choice(current)) => choice_ui(s, current, &tip, ui),
        _ => None,
    };
    if let Some(v) = new {
        // The widget made a value of the setting's own kind.
        let _ = p.render.set(s.key, &v);
    }
}

/// A checkbox "automatic" and, when it is off, a slider for the value.
fn auto_ui(
    p: &mut PanelParams,
    s: &'static Setting,
    widget: Widget,
    current: Option<f64>,
    ranges: Ranges,
    ui: &mut Ui,
) -> Option<Value> {
    let Widget::Auto {
        automatic,
        min,
        max,
        scene_length,
        manual,
    } = widget
    else {
        return None;
    };
    let (min, max) = if scene_length {
        (ranges.extent * min, ranges.extent * max)
    } else {
        (min, max)
    };
    let fallback = if scene_length { (min * max).sqrt() } else { manual };
    let mut value = *p.manual.entry(s.key).or_insert(current.unwrap_or(fallback));
    let mut auto = current.is_none();
    let tip = tooltip(s);
    let mut new = None;
    if ui.checkbox(&mut auto, automatic).on_hover_text(&tip).changed() {
        new = Some(Value::Auto((!auto).then_some(value)));
    }
    let slider = egui::Slider::new(&mut value, min..=max)
        .logarithmic(true)
        .text(s.label);
    if ui.add_enabled(!auto, slider).on_hover_text(&tip).changed() {
        p.manual.insert(s.key, value);
        new = Some(Value::Auto(Some(value)));
    }
    new
}

/// The setting's name and a button per choice.
fn choice_ui(s: &'static Setting, current: &'static str, tip: &str, ui: &mut Ui) -> Option<Value> {
    ui.horizontal(|ui| {
        ui.label(s.label).on_hover_text(tip);
        let mut chosen = None;
        for &(name, label, help) in s.choices {
            if ui
                .selectable_label(name == current, label)
                .on_hover_text(help)
                .clicked()
                && name != current
            {
                chosen = Some(Value::Choice(name));
            }
        }
        chosen
    })
    .inner
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::setting::Kind;

    #[test]
    fn every_shown_setting_has_a_widget_of_its_kind() {
        for s in SETTINGS {
            let fits = match (s.widget, s.kind) {
                (Widget::Hidden, _) => true,
                (Widget::Checkbox, Kind::Bool) => true,
                (Widget::Slider { .. }, Kind::Int | Kind::Real) => true,
                (Widget::Auto { .. }, Kind::Auto) => true,
                (Widget::Choice, Kind::Choice) => !s.choices.is_empty(),
                _ => false,
            };
            assert!(fits, "{}: {:?} cannot show {:?} values", s.key, s.widget, s.kind);
        }
    }
}
