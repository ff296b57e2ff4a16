//! Streaming frames to a running [tev](https://github.com/Tom94/tev) image viewer over its IPC
//! protocol (through the `tev_client` crate), the convention pbrt-v4's `--display-server` set:
//! the image is created once with its channels, then every frame replaces its pixels in strips
//! of rows. tev listens on 127.0.0.1:14158 unless started with another `--hostname`.

use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

use tev_client::{PacketCreateImage, PacketUpdateImage, TevClient};

use crate::render::Layer;

/// Where tev listens by default.
pub const DEFAULT_ADDRESS: &str = "127.0.0.1:14158";

/// Values per update packet at most (rows are grouped up to this): big frames go as several
/// packets, as pbrt's display server sends tiles, so no packet nears the protocol's 4 GiB.
const VALUES_PER_PACKET: usize = 1 << 22;

/// A connection to tev showing one image.
pub struct TevStream {
    client: TevClient,
    address: String,
    name: String,
    /// Size and channel names of the image tev holds (`None` before the first frame).
    created: Option<(u32, u32, Vec<String>)>,
}

/// Connecting to or sending to tev failed.
#[derive(Debug, thiserror::Error)]
#[error("tev at {address}: {message}")]
pub struct TevError {
    /// The address tried.
    pub address: String,
    /// What failed.
    pub message: String,
}

impl TevStream {
    /// Connects to tev at `address` (`HOST:PORT`), waiting at most 2 s; frames will appear as
    /// the image `name`.
    pub fn connect(address: &str, name: &str) -> Result<TevStream, TevError> {
        let error = |message: String| TevError {
            address: address.to_owned(),
            message,
        };
        let addrs: Vec<_> = address
            .to_socket_addrs()
            .map_err(|e| error(format!("not a HOST:PORT address ({e})")))?
            .collect();
        let mut last = error("the address resolves to nothing".into());
        for addr in addrs {
            match TcpStream::connect_timeout(&addr, Duration::from_secs(2)) {
                Ok(socket) => {
                    // A tev that stops reading must not hang the render.
                    let _ = socket.set_write_timeout(Some(Duration::from_secs(10)));
                    let _ = socket.set_nodelay(true);
                    return Ok(TevStream {
                        client: TevClient::wrap(socket),
                        address: address.to_owned(),
                        name: name.replace('\0', ""),
                        created: None,
                    });
                }
                Err(e) => last = error(format!("cannot connect ({e}); is tev running?")),
            }
        }
        Err(last)
    }

    /// Sends a frame: linear RGB plus single-channel `layers` (as `<name>.Y`), all
    /// `width × height`, rows from the top. The image is (re)created in tev when its size or
    /// channels change.
    pub fn send(
        &mut self,
        width: u32,
        height: u32,
        rgb: &[[f32; 3]],
        layers: &[Layer],
    ) -> Result<(), TevError> {
        let pixels = width as usize * height as usize;
        if pixels == 0 || rgb.len() != pixels || layers.iter().any(|l| l.values.len() != pixels) {
            return Err(self.error("the frame's channels do not match its size".into()));
        }
        let mut names: Vec<String> = ["R", "G", "B"].map(String::from).to_vec();
        names.extend(layers.iter().map(|l| format!("{}.Y", l.name)));
        let channels = names.len();
        let shape = (width, height, names.clone());
        if self.created.as_ref() != Some(&shape) {
            let packet = PacketCreateImage {
                image_name: &self.name,
                grab_focus: self.created.is_none(),
                width,
                height,
                channel_names: &names,
            };
            self.client.send(packet).map_err(|e| self.error(e.to_string()))?;
            self.created = Some(shape);
        }
        let offsets: Vec<u64> = (0..channels as u64).collect();
        let strides = vec![channels as u64; channels];
        let rows_per_packet = (VALUES_PER_PACKET / (width as usize * channels)).max(1);
        let mut data = Vec::new();
        for y0 in (0..height as usize).step_by(rows_per_packet) {
            let rows = rows_per_packet.min(height as usize - y0);
            let span = y0 * width as usize..(y0 + rows) * width as usize;
            data.clear();
            for k in span {
                data.extend_from_slice(&rgb[k]);
                data.extend(layers.iter().map(|l| l.values[k]));
            }
            let packet = PacketUpdateImage {
                image_name: &self.name,
                grab_focus: false,
                channel_names: &names,
                channel_offsets: &offsets,
                channel_strides: &strides,
                x: 0,
                y: y0 as u32,
                width,
                height: rows as u32,
                data: &data,
            };
            self.client.send(packet).map_err(|e| self.error(e.to_string()))?;
        }
        Ok(())
    }

    fn error(&self, message: String) -> TevError {
        TevError {
            address: self.address.clone(),
            message,
        }
    }
}

/// A decoded tev packet, as a test listener sees it (the inverse of what [`TevStream`] sends;
/// public so integration tests and tools can check a stream).
#[derive(Clone, Debug, PartialEq)]
pub enum Packet {
    /// Type 4: an image with named channels.
    Create {
        /// Image name.
        name: String,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// Channel names.
        channels: Vec<String>,
    },
    /// Type 6: a rectangle of pixels.
    Update {
        /// Image name.
        name: String,
        /// Channel names.
        channels: Vec<String>,
        /// Left column.
        x: u32,
        /// Top row.
        y: u32,
        /// Width of the rectangle.
        width: u32,
        /// Height of the rectangle.
        height: u32,
        /// The values, as sent.
        data: Vec<f32>,
    },
    /// Any other packet type.
    Other(u8),
}

/// Decodes one packet body (after its 4-byte length): the type byte and its fields.
pub fn decode_packet(body: &[u8]) -> Option<Packet> {
    let mut r = Reader { bytes: body, at: 0 };
    let kind = r.u8()?;
    match kind {
        4 => {
            let _grab_focus = r.u8()?;
            let name = r.string()?;
            let (width, height) = (r.u32()?, r.u32()?);
            let n = r.u32()?;
            let channels = (0..n).map(|_| r.string()).collect::<Option<_>>()?;
            Some(Packet::Create {
                name,
                width,
                height,
                channels,
            })
        }
        6 => {
            let _grab_focus = r.u8()?;
            let name = r.string()?;
            let n = r.u32()? as usize;
            let channels: Vec<String> = (0..n).map(|_| r.string()).collect::<Option<_>>()?;
            let (x, y, width, height) = (r.u32()?, r.u32()?, r.u32()?, r.u32()?);
            let offsets: Vec<u64> = (0..n).map(|_| r.u64()).collect::<Option<_>>()?;
            let strides: Vec<u64> = (0..n).map(|_| r.u64()).collect::<Option<_>>()?;
            let pixels = width as u64 * height as u64;
            let values = offsets
                .iter()
                .zip(&strides)
                .map(|(o, s)| o + pixels.saturating_sub(1) * s + 1)
                .max()?;
            let data = (0..values).map(|_| r.f32()).collect::<Option<_>>()?;
            Some(Packet::Update {
                name,
                channels,
                x,
                y,
                width,
                height,
                data,
            })
        }
        other => Some(Packet::Other(other)),
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let b = self.bytes.get(self.at..self.at + N)?.try_into().ok()?;
        self.at += N;
        Some(b)
    }
    fn u8(&mut self) -> Option<u8> {
        Some(self.take::<1>()?[0])
    }
    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take()?))
    }
    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take()?))
    }
    fn f32(&mut self) -> Option<f32> {
        Some(f32::from_le_bytes(self.take()?))
    }
    fn string(&mut self) -> Option<String> {
        let rest = self.bytes.get(self.at..)?;
        let end = rest.iter().position(|&b| b == 0)?;
        self.at += end + 1;
        Some(String::from_utf8_lossy(&rest[..end]).into_owned())
    }
}

/// Reads packets from a socket until it closes: each one's body decoded with
/// [`decode_packet`] (`None` for one that did not decode).
pub fn read_packets(mut socket: impl std::io::Read) -> Vec<Option<Packet>> {
    let mut packets = Vec::new();
    loop {
        let mut length = [0u8; 4];
        if socket.read_exact(&mut length).is_err() {
            return packets;
        }
        let length = u32::from_le_bytes(length) as usize;
        let mut body = vec![0u8; length.saturating_sub(4)];
        if socket.read_exact(&mut body).is_err() {
            return packets;
        }
        packets.push(decode_packet(&body));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::net::TcpListener;

    #[test]
    fn a_listener_receives_the_image_and_its_updates() {
        let listener = TcpListener::bind("127.0.0.1:0").expect("bind");
        let address = listener.local_addr().expect("addr").to_string();
        let reader = std::thread::spawn(move || read_packets(listener.accept().expect("accept").0));
        let mut stream = TevStream::connect(&address, "test.exr").expect("connect");
        let (w, h) = (3u32, 2u32);
        let rgb: Vec<[f32; 3]> = (0..6).map(|k| [k as f32, 0.0, 1.0]).collect();
        let radius = [0.5f32; 6];
        let layers = [Layer {
            name: "radius",
            values: &radius,
        }];
        stream.send(w, h, &rgb, &layers).expect("first frame");
        stream.send(w, h, &rgb, &layers).expect("second frame");
        drop(stream);
        let packets = reader.join().expect("reader");
        let names: Vec<String> = ["R", "G", "B", "radius.Y"].map(String::from).to_vec();
        assert_eq!(
            packets[0],
            Some(Packet::Create {
                name: "test.exr".into(),
                width: 3,
                height: 2,
                channels: names.clone()
            })
        );
        assert_eq!(packets.len(), 3, "one create, then one update per frame");
        let Some(Packet::Update {
            width,
            height,
            data,
            channels,
            ..
        }) = &packets[2]
        else {
            panic!("an update packet: {:?}", packets[2]);
        };
        assert_eq!((*width, *height, channels), (3, 2, &names));
        assert_eq!(&data[4..8], &[1.0, 0.0, 1.0, 0.5], "pixel 1: R, G, B, radius");
    }

    #[test]
    fn a_refused_connection_is_an_error_naming_the_address() {
        let listener = TcpListener::bind("127.0.0.1:0").expect("bind");
        let address = listener.local_addr().expect("addr").to_string();
        drop(listener);
        let e = TevStream::connect(&address, "x").err().expect("refused");
        assert!(e.to_string().contains(&address), "{e}");
        assert!(TevStream::connect("no port here", "x").is_err());
    }
}
