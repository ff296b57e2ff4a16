//! What the viewer does for the Design panel ([`super::design`]): choosing the target (a file
//! dialog), starting and stopping a design, putting its moves into the scene as it runs (the
//! render follows with warm restarts) and recording the whole design as one undo step.

use super::design::{DesignRun, DesignUpdate, MOVE_AT_LEAST_EVERY};
use super::editor::Edit;
use super::file_dialog::{take_finished, FileDialog, FileRequest, Finished};
use super::state::Status;
use super::viewer::Viewer;

impl Viewer {
    /// Shows the open dialog for a design's target image.
    pub fn pick_design_target(&mut self) {
        if self.design.picking.is_some() {
            return;
        }
        let request = FileRequest {
            title: "Target image for the design".into(),
            filters: vec![(
                "Images".into(),
                ["png", "jpg", "jpeg", "exr", "pfm"].map(String::from).to_vec(),
            )],
            directory: self.settings.last_directory.clone(),
            file_name: None,
            save: false,
            folder: false,
        };
        let native = self.native_dialog();
        self.state.design.picking = Some(FileDialog::open(
            "caustic-design-target-dialog",
            &self.ctx,
            native,
            request,
        ));
    }

    /// Starts designing the panel's surface for its target on its receiver (nothing when one
    /// is running; a message in the panel when something is missing).
    pub fn start_design(&mut self) {
        if self.design_run.is_some() {
            return;
        }
        let scene = self.document.scene();
        let (surface, receiver) = self
            .design
            .choice(scene, super::design_panel::selected_object(&self.state));
        let missing = match (&surface, &receiver, self.design.target()) {
            (None, _, _) => Some("the scene has no patches of smooth glass or mirror to design"),
            (_, None, _) => Some("the scene has no quad for the light to draw on"),
            (_, _, None) => Some("choose a target image first"),
            _ => None,
        };
        if let Some(why) = missing {
            self.state.design.message = Some(Err(why.into()));
            return;
        }
        let (Some(surface), Some(receiver), Some(target)) =
            (surface, receiver, self.design.target().cloned())
        else {
            return;
        };
        let run = DesignRun::spawn(
            &self.ctx,
            scene.clone(),
            (surface.clone(), receiver.clone(), target.clone()),
            self.design.steps(),
        );
        let design = &mut self.state.design;
        design.running = true;
        design.losses.clear();
        design.latest = None;
        design.parameters = 0;
        design.message = Some(Ok(format!(
            "Designing '{surface}' to draw {} on '{receiver}'...",
            target.display()
        )));
        self.design_run = Some(run);
    }

    /// Asks the running design to end after its step (its moves so far are kept).
    pub fn stop_design(&mut self) {
        if let Some(run) = &self.design_run {
            run.stop();
        }
    }

    /// Takes the target dialog's answer and the running design's reports; call once per UI
    /// frame.
    pub(super) fn poll_design(&mut self) {
        match take_finished(&mut self.state.design.picking) {
            Some(Finished::Chosen(path)) => {
                self.remember_folder_of(&path);
                self.state.design.target = Some(path);
            }
            Some(Finished::Lost) => self.status = Some(Status::Error("the file dialog failed".into())),
            Some(Finished::Cancelled) | None => {}
        }
        let Some(run) = &mut self.design_run else {
            return;
        };
        let mut theta = None;
        let mut ended = None;
        let mut lost = false;
        loop {
            match run.updates.try_recv() {
                Ok(DesignUpdate::Started(moved)) => {
                    let handles: Vec<_> = moved.iter().flat_map(|m| m.handles.iter().copied()).collect();
                    run.start = handles
                        .into_iter()
                        .map(|h| (h, self.state.editor.point(&self.state.document, h)))
                        .collect();
                    self.state.design.parameters = moved.len();
                    run.moved = moved;
                }
                Ok(DesignUpdate::Step(report, moves)) => {
                    self.state.design.losses.push([report.step as f64, report.loss]);
                    self.state.design.latest = Some(report);
                    theta = moves.or(theta);
                }
                Ok(end @ (DesignUpdate::Finished { .. } | DesignUpdate::Failed(_))) => {
                    ended = Some(end);
                    break;
                }
                Err(crossbeam_channel::TryRecvError::Empty) => break,
                Err(crossbeam_channel::TryRecvError::Disconnected) => {
                    lost = true;
                    break;
                }
            }
        }
        if let Some(newer) = theta {
            run.waiting = Some(newer);
        }
        if let Some(DesignUpdate::Finished { theta: last, .. }) = &ended {
            run.waiting = Some(last.clone());
        }
        // The render draws each state of the surface before it sees the next.
        let drawn = !self.state.restart_pending() || self.state.paused();
        let due = drawn || run.applied.elapsed() >= MOVE_AT_LEAST_EVERY || ended.is_some();
        if let Some(theta) = run.waiting.take_if(|_| due) {
            run.applied = std::time::Instant::now();
            let moves = run.positions(&theta);
            self.move_points(&moves);
        }
        match ended {
            Some(DesignUpdate::Finished {
                initial_loss,
                final_loss,
                ..
            }) => {
                let steps = self.design.latest.map_or(0, |r| r.step + 1);
                self.end_design(Ok(format!(
                    "Designed in {steps} steps: loss from {initial_loss:.4} to {final_loss:.4} ({:.1} % of the start). Undo (Ctrl+Z) puts the surface back.",
                    100.0 * final_loss / initial_loss
                )));
            }
            Some(DesignUpdate::Failed(why)) => self.end_design(Err(why)),
            _ if lost => self.end_design(Err("the design stopped unexpectedly".into())),
            _ => {}
        }
    }

    /// Ends the design: what it moved becomes one undo step.
    fn end_design(&mut self, message: Result<String, String>) {
        let Some(run) = self.design_run.take() else {
            return;
        };
        let moves = run
            .start
            .into_iter()
            .map(|(h, before)| (h, before, self.state.editor.point(&self.state.document, h)))
            .filter(|(_, a, b)| a != b)
            .collect();
        self.record(Edit::Points(moves));
        self.state.design.running = false;
        self.state.design.message = Some(message);
    }

    /// Stops a running design and forgets it (the scene it shapes is being replaced).
    pub(super) fn abandon_design(&mut self) {
        if let Some(run) = self.design_run.take() {
            run.stop();
            self.state.design.running = false;
            self.state.design.message = Some(Err("the design was stopped: another scene was opened".into()));
        }
    }
}
