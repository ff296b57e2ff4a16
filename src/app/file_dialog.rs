//! File dialogs that always open: the desktop's own (rfd: the xdg-desktop-portal, or zenity
//! without one) on a thread, and, where no native dialog can be shown (a plain X session, a
//! minimal window manager, a remote display), a file dialog inside the window with a folder
//! listing and a file name field that completes with Tab.
//!
//! rfd answers "no file" both when the person cancels and when it could show nothing; a
//! native dialog that answers within [`SHOWN_AT_LEAST`] never was on screen (no person
//! cancels that fast), so the window's own dialog opens instead of reporting a cancel.
//! `CAUSTIC_FILE_DIALOG=in-window` always uses the window's own.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use super::job::{Job, Poll};

/// A native dialog that returns "nothing" sooner than this was never shown.
pub const SHOWN_AT_LEAST: Duration = Duration::from_millis(150);

/// What a dialog asks for.
#[derive(Clone, Debug, PartialEq)]
pub struct FileRequest {
    /// Window title ("Save frame").
    pub title: String,
    /// Named filters: a description and its extensions (without the dot).
    pub filters: Vec<(String, Vec<String>)>,
    /// Folder to start in.
    pub directory: Option<PathBuf>,
    /// File name to propose (save dialogs).
    pub file_name: Option<String>,
    /// A save dialog (a new file name) rather than an open one (an existing file).
    pub save: bool,
    /// A folder is chosen, not a file (`save` is then ignored).
    pub folder: bool,
}

/// How a native dialog is shown: returns the chosen path, or `None` for a cancel or when it
/// could not be shown at all. [`rfd_dialog`] in the program; tests pass their own.
pub type NativeDialog = fn(&FileRequest) -> Option<PathBuf>;

/// The desktop's dialog through rfd (blocking: run it off the UI thread). Honours
/// `CAUSTIC_FILE_DIALOG=in-window` by showing nothing.
pub fn rfd_dialog(request: &FileRequest) -> Option<PathBuf> {
    if std::env::var("CAUSTIC_FILE_DIALOG").is_ok_and(|v| v == "in-window") {
        return None;
    }
    let mut dialog = rfd::FileDialog::new().set_title(&request.title);
    for (name, extensions) in &request.filters {
        dialog = dialog.add_filter(name, extensions);
    }
    if let Some(name) = &request.file_name {
        dialog = dialog.set_file_name(name);
    }
    if let Some(dir) = &request.directory {
        dialog = dialog.set_directory(dir);
    }
    if request.folder {
        dialog.pick_folder()
    } else if request.save {
        dialog.save_file()
    } else {
        dialog.pick_file()
    }
}

/// What a native dialog's answer means.
#[derive(Clone, Debug, PartialEq)]
pub enum NativeAnswer {
    /// A file was chosen.
    Chosen(PathBuf),
    /// The person closed the dialog without a choice.
    Cancelled,
    /// No dialog was shown.
    Unavailable,
}

impl NativeAnswer {
    /// Reads a native dialog's result given how long it was open.
    pub fn from_result(result: Option<PathBuf>, open_for: Duration) -> Self {
        match result {
            Some(path) => NativeAnswer::Chosen(path),
            None if open_for < SHOWN_AT_LEAST => NativeAnswer::Unavailable,
            None => NativeAnswer::Cancelled,
        }
    }
}

enum State {
    Native(Job<NativeAnswer>),
    InWindow(Box<InWindow>),
}

/// One file dialog under way: native on a thread, or the window's own once the native one
/// could not be shown. The viewer polls it each frame and draws it with [`FileDialog::ui`].
pub struct FileDialog {
    state: RefCell<State>,
    request: FileRequest,
}

impl FileDialog {
    /// Opens `request` with `native`, on a thread named `name`.
    pub fn open(name: &str, ctx: &egui::Context, native: NativeDialog, request: FileRequest) -> Self {
        let asked = request.clone();
        let job = Job::spawn(name, ctx, move || {
            let start = Instant::now();
            let result = native(&asked);
            NativeAnswer::from_result(result, start.elapsed())
        });
        Self {
            state: RefCell::new(State::Native(job)),
            request,
        }
    }

    /// The chosen file (`Some`), a cancel (`None`), still open, or a lost dialog thread.
    pub fn poll(&self) -> Poll<Option<PathBuf>> {
        let mut state = self.state.borrow_mut();
        match &mut *state {
            State::Native(job) => match job.poll() {
                Poll::Pending => Poll::Pending,
                Poll::Lost => Poll::Lost,
                Poll::Ready(NativeAnswer::Chosen(path)) => Poll::Ready(Some(path)),
                Poll::Ready(NativeAnswer::Cancelled) => Poll::Ready(None),
                Poll::Ready(NativeAnswer::Unavailable) => {
                    *state = State::InWindow(Box::new(InWindow::new(self.request.clone())));
                    Poll::Pending
                }
            },
            State::InWindow(window) => match window.answer.take() {
                Some(answer) => Poll::Ready(answer),
                None => Poll::Pending,
            },
        }
    }

    /// Whether the window's own dialog is showing.
    pub fn in_window(&self) -> bool {
        matches!(&*self.state.borrow(), State::InWindow(_))
    }

    /// Draws the window's own dialog, when it is the one open.
    pub fn ui(&self, ctx: &egui::Context) {
        if let State::InWindow(window) = &mut *self.state.borrow_mut() {
            window.ui(ctx);
        }
    }
}

/// How a dialog ended ([`take_finished`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Finished {
    /// A file (or folder) was chosen.
    Chosen(PathBuf),
    /// The person closed it without a choice.
    Cancelled,
    /// Its thread ended without an answer.
    Lost,
}

/// The dialog in `slot` if it has ended, taken out of the slot: how it ended. `None` while it
/// is open, or when there is none.
pub fn take_finished(slot: &mut Option<FileDialog>) -> Option<Finished> {
    let finished = match slot.as_ref()?.poll() {
        Poll::Pending => return None,
        Poll::Ready(Some(path)) => Finished::Chosen(path),
        Poll::Ready(None) => Finished::Cancelled,
        Poll::Lost => Finished::Lost,
    };
    *slot = None;
    Some(finished)
}

/// One entry of the folder listing.
#[derive(Clone, Debug, PartialEq)]
struct Entry {
    name: String,
    folder: bool,
}

/// The file dialog drawn inside the window.
struct InWindow {
    request: FileRequest,
    folder: PathBuf,
    folder_text: String,
    name: String,
    entries: Vec<Entry>,
    message: Option<String>,
    /// Set once the person chose (`Some(path)`) or cancelled (`None`).
    answer: Option<Option<PathBuf>>,
    /// Whether the name field has been given the keyboard (on the first frame).
    focused: bool,
}

impl InWindow {
    fn new(request: FileRequest) -> Self {
        let folder = request
            .directory
            .clone()
            .filter(|d| d.is_dir())
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_else(|| PathBuf::from("/"));
        let mut window = Self {
            name: request.file_name.clone().unwrap_or_default(),
            request,
            folder_text: String::new(),
            folder: PathBuf::new(),
            entries: Vec::new(),
            message: None,
            answer: None,
            focused: false,
        };
        window.enter(folder);
        window
    }

    /// Whether `name` passes the filters (folders always do).
    fn shown(&self, name: &str) -> bool {
        let ext = Path::new(name)
            .extension()
            .map(|e| e.to_string_lossy().to_lowercase());
        self.request.filters.is_empty()
            || self
                .request
                .filters
                .iter()
                .flat_map(|(_, exts)| exts)
                .any(|e| ext.as_deref() == Some(e.as_str()))
    }

    /// Lists `folder` (folders first, then the files the filters pass; hidden ones left out).
    fn enter(&mut self, folder: PathBuf) {
        match std::fs::read_dir(&folder) {
            Ok(read) => {
                let mut entries: Vec<Entry> = read
                    .flatten()
                    .map(|e| Entry {
                        name: e.file_name().to_string_lossy().into_owned(),
                        folder: e.path().is_dir(),
                    })
                    .filter(|e| !e.name.starts_with('.') && (e.folder || self.shown(&e.name)))
                    .collect();
                entries.sort_by(|a, b| (!a.folder, &a.name).cmp(&(!b.folder, &b.name)));
                self.entries = entries;
                self.folder_text = folder.display().to_string();
                self.folder = folder;
                self.message = None;
            }
            Err(e) => self.message = Some(format!("{}: {e}", folder.display())),
        }
    }

    /// Completes the file name from the listing: into the one folder it names, or to the
    /// longest prefix the matching entries share.
    fn complete(&mut self) {
        let matches: Vec<&Entry> = self
            .entries
            .iter()
            .filter(|e| e.name.starts_with(&self.name))
            .collect();
        match matches.as_slice() {
            [] => self.message = Some(format!("nothing here starts with '{}'", self.name)),
            [one] if one.folder => {
                let next = self.folder.join(&one.name);
                self.name.clear();
                self.enter(next);
            }
            [one] => self.name = one.name.clone(),
            many => {
                let first = &many[0].name;
                let common = many.iter().fold(first.len(), |n, e| {
                    first
                        .bytes()
                        .zip(e.name.bytes())
                        .take(n)
                        .take_while(|(a, b)| a == b)
                        .count()
                });
                self.name = first[..common].to_owned();
            }
        }
    }

    /// Takes the file name as the answer, or explains why not.
    fn confirm(&mut self) {
        let name = self.name.trim();
        if self.request.folder {
            let path = self.folder.join(name);
            if path.is_dir() {
                self.answer = Some(Some(path));
            } else {
                self.message = Some(format!("{}: no such folder", path.display()));
            }
            return;
        }
        if name.is_empty() {
            self.message = Some("type a file name, or pick one above".to_owned());
            return;
        }
        let path = self.folder.join(name);
        if path.is_dir() {
            self.name.clear();
            self.enter(path);
        } else if !self.request.save && !path.is_file() {
            self.message = Some(format!("{}: no such file", path.display()));
        } else if self.request.save && !path.parent().is_some_and(Path::is_dir) {
            self.message = Some(format!("{}: the folder does not exist", path.display()));
        } else {
            self.answer = Some(Some(path));
        }
    }

    fn ui(&mut self, ctx: &egui::Context) {
        let mut open = true;
        egui::Window::new(self.request.title.clone())
            .id(egui::Id::unique("caustic-file-dialog"))
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
            .open(&mut open)
            .show(ctx, |ui| self.contents_ui(ui));
        if !open || ctx.input(|i| i.key_pressed(egui::Key::Escape)) {
            self.answer = Some(None);
        }
    }

    /// The folder field and "Up"; whether the field took this frame's Enter (to go there).
    fn folder_row_ui(&mut self, ui: &mut egui::Ui, enter: bool) -> bool {
        let mut took = false;
        ui.horizontal(|ui| {
            let label = ui.label("Folder:");
            let field = ui.add(egui::TextEdit::singleline(&mut self.folder_text).desired_width(360.0));
            let field = field.labelled_by(label.id);
            if field.lost_focus() && enter {
                took = true;
                self.enter(PathBuf::from(self.folder_text.clone()));
            }
            if ui.button("Up").on_hover_text("The folder above").clicked() {
                if let Some(parent) = self.folder.parent().map(Path::to_path_buf) {
                    self.enter(parent);
                }
            }
        });
        took
    }

    /// The file name field: Tab completes it; on the first frame it takes the keyboard with
    /// the name's stem selected. Whether Enter confirmed the name in it.
    fn name_row_ui(&mut self, ui: &mut egui::Ui, enter: bool) -> bool {
        let mut confirmed = false;
        ui.horizontal(|ui| {
            let label = ui.label("File name:");
            let id = egui::Id::unique("caustic-file-dialog-name");
            // Tab completes the name (before the field would pass the focus on).
            if ui.memory(|m| m.has_focus(id))
                && ui.input_mut(|i| i.consume_key(egui::Modifiers::NONE, egui::Key::Tab))
            {
                self.complete();
            }
            let mut output = egui::TextEdit::singleline(&mut self.name)
                .id(id)
                .desired_width(340.0)
                .show(ui);
            if !self.focused {
                // The dialog opens with the keyboard in the name field and the name's stem
                // selected, so typing replaces the stem and keeps the extension.
                self.focused = true;
                let stem = match self.name.rfind('.') {
                    Some(dot) if dot > 0 => self.name[..dot].chars().count(),
                    _ => self.name.chars().count(),
                };
                let range = egui::text_selection::CCursorRange::two(
                    egui::text::CCursor::new(0),
                    egui::text::CCursor::new(stem),
                );
                output.state.cursor.set_char_range(Some(range));
                output.state.store(ui.ctx(), id);
                output.response.request_focus();
            }
            let field = output.response.response.clone().labelled_by(label.id);
            confirmed = field.lost_focus() && enter;
        });
        confirmed
    }

    fn contents_ui(&mut self, ui: &mut egui::Ui) {
        let enter = ui.input(|i| i.key_pressed(egui::Key::Enter));
        let folder_took_enter = self.folder_row_ui(ui, enter);
        let mut chosen: Option<Entry> = None;
        egui::ScrollArea::vertical().max_height(220.0).show(ui, |ui| {
            ui.set_min_width(440.0);
            for entry in &self.entries {
                let text = if entry.folder {
                    format!("{}/", entry.name)
                } else {
                    entry.name.clone()
                };
                if ui.selectable_label(entry.name == self.name, text).clicked() {
                    chosen = Some(entry.clone());
                }
            }
            if self.entries.is_empty() {
                ui.weak("(no folders or matching files here)");
            }
        });
        match chosen {
            Some(e) if e.folder => self.enter(self.folder.join(&e.name)),
            Some(e) => self.name = e.name,
            None => {}
        }
        let types: Vec<String> = self
            .request
            .filters
            .iter()
            .map(|(name, exts)| format!("{name} (.{})", exts.join(", .")))
            .collect();
        ui.weak(format!("Types: {}", types.join("; ")));
        let named = self.name_row_ui(ui, enter);
        // Enter takes the name wherever the keyboard is, unless the folder field used it.
        let mut confirm = named || (enter && !folder_took_enter && ui.memory(|m| m.focused().is_none()));
        if let Some(message) = &self.message {
            ui.colored_label(ui.visuals().warn_fg_color, message);
        }
        ui.horizontal(|ui| {
            let verb = match (self.request.folder, self.request.save) {
                (true, _) => "Choose this folder",
                (false, true) => "Save",
                (false, false) => "Open",
            };
            confirm |= ui.button(verb).clicked();
            if ui.button("Cancel").clicked() {
                self.answer = Some(None);
            }
        });
        if confirm {
            self.confirm();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_instant_none_is_no_dialog_and_a_slow_one_a_cancel() {
        assert_eq!(
            NativeAnswer::from_result(None, Duration::from_millis(3)),
            NativeAnswer::Unavailable
        );
        assert_eq!(
            NativeAnswer::from_result(None, Duration::from_secs(2)),
            NativeAnswer::Cancelled
        );
        let p = PathBuf::from("/tmp/a.png");
        assert_eq!(
            NativeAnswer::from_result(Some(p.clone()), Duration::ZERO),
            NativeAnswer::Chosen(p)
        );
    }

    #[test]
    fn tab_completes_to_the_shared_prefix_and_enters_a_lone_folder() {
        let dir = tempfile::tempdir().expect("temp dir");
        for name in ["frame-001.png", "frame-002.png", "notes.txt"] {
            std::fs::write(dir.path().join(name), b"x").expect("writes");
        }
        std::fs::create_dir(dir.path().join("renders")).expect("makes");
        let mut w = InWindow::new(FileRequest {
            title: "Save frame".into(),
            filters: vec![("PNG".into(), vec!["png".into()])],
            directory: Some(dir.path().to_path_buf()),
            file_name: Some("fr".into()),
            save: true,
            folder: false,
        });
        // The text file is filtered out; folders come first.
        let names: Vec<&str> = w.entries.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(names, ["renders", "frame-001.png", "frame-002.png"]);
        w.complete();
        assert_eq!(w.name, "frame-00");
        w.name = "re".into();
        w.complete();
        assert_eq!(w.folder, dir.path().join("renders"));
        assert_eq!(w.name, "");
        w.name = "new.png".into();
        w.confirm();
        assert_eq!(w.answer, Some(Some(dir.path().join("renders/new.png"))));
    }
}
