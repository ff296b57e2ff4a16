//! Everything a person can ask of the viewer, as data: menus, panels, keys, the mouse over
//! the image and scripted runs emit [`Action`]s; `Viewer::apply` (`apply.rs`) is the one place
//! that carries them out (changing the viewer's state, telling the render session, recording
//! undo steps). Undo and redo replay inverse edits through the same code.

use std::path::PathBuf;

use egui::{Pos2, Vec2};
use glam::DVec3;

use super::editor::CameraMove;
use super::handle::Handle;
use super::params::PanelParams;
use super::settings::{DisplayMode, Zoom};

/// What an unsaved-edits question was asked for.
#[derive(Clone, Debug, PartialEq)]
pub enum AfterDiscard {
    /// Open this scene.
    Open(PathBuf),
    /// Show the open dialog.
    Pick,
    /// Close the window.
    Close,
}

/// A request to the viewer.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Show the open dialog (asks first when there are unsaved edits).
    PickScene,
    /// Open a scene file (asks first when there are unsaved edits).
    OpenScene(PathBuf),
    /// Show the folder dialog for a render folder to watch.
    PickWatchFolder,
    /// Watch this render folder: show its parts merged as they land (`view --watch`).
    WatchFolder(PathBuf),
    /// Stop watching the render folder and render the scene again.
    StopWatching,
    /// Show this render of the watched folder (`None`: the one most parts belong to).
    WatchRender(Option<crate::render::shard::RenderKey>),
    /// Show the open dialog for a reference image (.exr, .pfm).
    PickReference,
    /// Compare with this reference image.
    OpenReference(PathBuf),
    /// Stop comparing with the reference.
    CloseReference,
    /// Show the reference instead of the render (`true`), or the render (A/B).
    ShowReference(bool),
    /// Send the current frame to tev at this address.
    SendToTev(String),
    /// Show the save dialog for the current frame.
    SaveFrame,
    /// Answer the frame overwrite question (`true`: replace).
    ConfirmFrameOverwrite(bool),
    /// Save the scene to its own file (asks before replacing it), or ask where.
    SaveScene,
    /// Ask where to save the scene.
    SaveSceneAs,
    /// Save the scene to this file (asks before replacing one).
    SaveSceneTo(PathBuf),
    /// Answer the scene overwrite question (`true`: replace).
    ConfirmSceneOverwrite(bool),
    /// Answer the unsaved-edits question: `Some(true)` discard and go on, `Some(false)` save
    /// first, `None` cancel.
    ResolveUnsaved(Option<bool>),
    /// Close the window (asks first when there are unsaved edits).
    Close,
    /// New parameter values (the differences become session commands).
    SetParams(PanelParams),
    /// Discard the accumulation and render again.
    Restart,
    /// Restart, asking first when passes would be thrown away (the `R` key).
    AskRestart,
    /// The answer to [`Action::AskRestart`]'s question: restart or not.
    ConfirmRestart(bool),
    /// Start a fresh render session (after a failure).
    RestartRenderer,
    /// Close the "could not open scene" window.
    DismissSceneError,
    /// Exposure in stops.
    SetExposure(f32),
    /// Image placement; `recentre` also clears the pan.
    SetZoom {
        /// New zoom.
        zoom: Zoom,
        /// Clear the pan.
        recentre: bool,
    },
    /// What the image shows.
    SetDisplay(DisplayMode),
    /// Side panel shown or hidden.
    ShowSidePanel(bool),
    /// Help window shown or hidden.
    ShowHelp(bool),
    /// Control-net overlay shown or hidden.
    ShowWireframe(bool),
    /// The handle (control point or light) under the cursor changed.
    Hover(Option<Handle>),
    /// Select a handle; `add` toggles it in the selection instead of replacing it.
    Select {
        /// The handle.
        point: Handle,
        /// Shift held.
        add: bool,
    },
    /// Select every control point of a patch.
    SelectPatch(usize),
    /// Select nothing.
    ClearSelection,
    /// A Shift + left drag on empty space: the rectangle from `from` to `to` (screen points);
    /// when `done`, every handle inside joins the selection.
    BoxSelect {
        /// Where the drag began.
        from: Pos2,
        /// Where the pointer is.
        to: Pos2,
        /// The button was released.
        done: bool,
    },
    /// A drag begins on a handle.
    BeginPointDrag {
        /// The grabbed handle.
        grab: Handle,
        /// Where the button went down (points).
        press: Pos2,
    },
    /// The cursor of a point drag moved; `along_view` moves along the line of sight.
    DragPoints {
        /// Cursor.
        pointer: Pos2,
        /// Ctrl held.
        along_view: bool,
    },
    /// A camera drag begins.
    BeginCameraDrag(CameraMove),
    /// The cursor of a camera drag moved this far since it began (points).
    DragCamera(Vec2),
    /// The mouse was released: the gesture becomes one undo step.
    EndGesture,
    /// Put a handle at an exact position (the panel's fields).
    SetPoint(Handle, DVec3),
    /// Move the selection by a step in screen points (arrow keys).
    Nudge(Vec2),
    /// Give material `material` new numbers (the panel's material controls); the steps of
    /// one slider drag (the same `drag` token) are one undo step.
    SetMaterial {
        /// Material index in the scene.
        material: usize,
        /// The material as it is to be.
        value: crate::scene::Material,
        /// The drag it is a step of (a token unique to one press of the mouse), if any.
        drag: Option<u64>,
    },
    /// Turn and move the camera to frame the selection (or every patch).
    FrameSelection,
    /// Undo the last edit.
    Undo,
    /// Redo the last undone edit.
    Redo,
    /// Show the open dialog for a design's target image.
    PickDesignTarget,
    /// Design for this target image.
    SetDesignTarget(PathBuf),
    /// Design this object (a `patches` object of smooth glass or mirror).
    SetDesignSurface(String),
    /// Draw on this object (a quad).
    SetDesignReceiver(String),
    /// Take this many steps of the descent.
    SetDesignSteps(usize),
    /// Start designing the surface for the target.
    StartDesign,
    /// Stop the running design, keeping its moves so far.
    StopDesign,
}

impl Action {
    /// Whether the action is the Design panel's (its choices, Start, Stop).
    pub fn is_design(&self) -> bool {
        matches!(
            self,
            Action::PickDesignTarget
                | Action::SetDesignTarget(_)
                | Action::SetDesignSurface(_)
                | Action::SetDesignReceiver(_)
                | Action::SetDesignSteps(_)
                | Action::StartDesign
                | Action::StopDesign
        )
    }

    /// Whether the action edits the scene's geometry, lights or materials, or undoes or redoes
    /// such an edit: what a running design refuses, since it is shaping the scene.
    pub fn edits_the_scene(&self) -> bool {
        matches!(
            self,
            Action::BeginPointDrag { .. }
                | Action::DragPoints { .. }
                | Action::SetPoint(..)
                | Action::Nudge(_)
                | Action::SetMaterial { .. }
                | Action::Undo
                | Action::Redo
        )
    }
}
