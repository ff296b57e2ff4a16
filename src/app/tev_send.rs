//! "Send frame to tev": the current frame (radiance, search radius, photon count) to a running
//! tev, on a thread, the status bar saying how it went — the viewer's side of the tev
//! streaming `caustic render --tev` does ([`crate::tev`]).

use super::job::{Job, Poll};
use super::viewer::{Status, Viewer};
use crate::render::Layer;
use crate::tev::TevStream;

/// A send under way: its result is the address it reached, or why it failed.
#[derive(Default)]
pub struct TevSend {
    job: Option<Job<Result<String, String>>>,
}

impl TevSend {
    /// Whether a send is under way.
    pub fn busy(&self) -> bool {
        self.job.is_some()
    }
}

impl Viewer {
    /// Sends the current frame to tev at `address` (`HOST:PORT`) as the image
    /// `caustic: <scene file>`.
    pub fn send_to_tev(&mut self, address: &str) {
        let Some(frame) = self.frame.clone() else {
            self.status = Some(Status::Error("nothing to send yet: no frame has arrived".into()));
            return;
        };
        if self.tev.job.is_some() {
            return;
        }
        let name = format!(
            "caustic: {}",
            self.scene
                .source
                .file_name()
                .map_or("scene".into(), |n| n.to_string_lossy())
        );
        let address = address.to_owned();
        self.tev.job = Some(Job::spawn("caustic-tev", &self.ctx, move || {
            let mut stream = TevStream::connect(&address, &name).map_err(|e| e.to_string())?;
            let layers = [
                Layer {
                    name: "radius",
                    values: &frame.radius,
                },
                Layer {
                    name: "photons",
                    values: &frame.gathered,
                },
            ];
            stream
                .send(frame.width, frame.height, &frame.radiance, &layers)
                .map_err(|e| e.to_string())?;
            Ok(address)
        }));
    }

    /// Takes a finished send; call once per UI frame.
    pub(super) fn poll_tev(&mut self) {
        let Some(job) = &self.tev.job else {
            return;
        };
        let result = match job.poll() {
            Poll::Pending => return,
            Poll::Ready(r) => r,
            Poll::Lost => Err("sending to tev failed unexpectedly".into()),
        };
        self.tev.job = None;
        self.status = Some(match result {
            Ok(address) => Status::Info(format!("Sent the frame to tev at {address}")),
            Err(e) => Status::Error(format!("Not sent: {e}")),
        });
    }
}
