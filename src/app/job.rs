//! Work off the UI thread (file dialogs, scene loading, image writing): a thread whose one
//! result the UI polls each frame, waking the UI when it is ready.

use crossbeam_channel::{bounded, Receiver, TryRecvError};

/// A background computation with one result.
pub struct Job<T> {
    result: Receiver<T>,
}

/// What polling a job found.
pub enum Poll<T> {
    /// Still running.
    Pending,
    /// Finished with this result.
    Ready(T),
    /// The thread ended without a result (it panicked).
    Lost,
}

impl<T: Send + 'static> Job<T> {
    /// Runs `work` on a thread named `name`, then asks `ctx` for a repaint.
    pub fn spawn(name: &str, ctx: &egui::Context, work: impl FnOnce() -> T + Send + 'static) -> Self {
        let (tx, result) = bounded(1);
        let ctx = ctx.clone();
        // If the thread cannot start, the sender is dropped with the closure and the job
        // reads as lost, which the UI reports.
        let _ = std::thread::Builder::new().name(name.to_owned()).spawn(move || {
            let _ = tx.send(work());
            ctx.request_repaint();
        });
        Self { result }
    }

    /// Takes the result if it is there.
    pub fn poll(&self) -> Poll<T> {
        match self.result.try_recv() {
            Ok(v) => Poll::Ready(v),
            Err(TryRecvError::Empty) => Poll::Pending,
            Err(TryRecvError::Disconnected) => Poll::Lost,
        }
    }

    /// Waits for the result (tests, and the final flush on exit).
    pub fn wait(self) -> Option<T> {
        self.result.recv().ok()
    }
}
