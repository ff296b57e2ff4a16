//! "Send frame to tev": the current frame (radiance, search radius, photon count) to a running
//! tev, on a thread, the status bar saying how it went — the viewer's side of the tev
//! streaming `caustic render --tev` does ([`crate::tev`]).

use super::job::{Job, Poll};
use super::state::Status;
use crate::render::session::Frame;
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

impl TevSend {
    /// Sends `frame` to tev at `address` (`HOST:PORT`) as the image `name`, on a thread;
    /// `None` when a send is already under way.
    pub fn send(&mut self, ctx: &egui::Context, frame: Frame, name: String, address: &str) -> Option<()> {
        if self.job.is_some() {
            return None;
        }
        let address = address.to_owned();
        self.job = Some(Job::spawn("caustic-tev", ctx, move || {
            let mut stream = TevStream::connect(&address, &name).map_err(|e| e.to_string())?;
            let layers: Vec<Layer> = frame
                .layers
                .iter()
                .map(|l| Layer {
                    name: l.name,
                    values: &l.values,
                })
                .collect();
            stream
                .send(frame.width, frame.height, &frame.radiance, &layers)
                .map_err(|e| e.to_string())?;
            Ok(address)
        }));
        Some(())
    }

    /// The status line of a finished send, if one finished; call once per UI frame.
    pub fn poll(&mut self) -> Option<Status> {
        let job = self.job.as_ref()?;
        let result = match job.poll() {
            Poll::Pending => return None,
            Poll::Ready(r) => r,
            Poll::Lost => Err("sending to tev failed unexpectedly".into()),
        };
        self.job = None;
        Some(match result {
            Ok(address) => Status::Info(format!("Sent the frame to tev at {address}")),
            Err(e) => Status::Error(format!("Not sent: {e}")),
        })
    }
}
