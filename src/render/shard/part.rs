//! The part file: an OpenEXR image that a shard (`caustic render --shard K/N`) or a merge
//! (`caustic merge`) writes. It holds
//! - `R`, `G`, `B`: the mean of its passes as f32 (so any EXR viewer shows the part);
//! - the exact fixed-point sums of [`PassSums`], each 128-bit sum as four `u32` channels
//!   (`caustic.sum.R.w0` … `w3`, least significant word first; `R`, `G`, `B`, and `Y2` for
//!   luminance squared);
//! - string attributes: the image's provenance ([`crate::render::provenance`]: program version,
//!   effective scene text, seed, size) and the part's own keys below: its pass list, the
//!   render's total passes, photons emitted, the scene text's hash and the render settings.
//!
//! Parts merge when they come from the same program version, image size, settings, scene
//! and total pass count, and hold no pass in common ([`Part::check_joins`]); the merge is a
//! part too, so merges merge again.

use std::path::{Path, PathBuf};

use super::sums::{parse_passes, passes_text, PassSums, SumsClash};
use crate::render::film::{exr_text_attributes, Metadata};
use crate::render::provenance;
use crate::settings::{RenderParams, RendererKind};

/// Marks a part file (its format version).
pub const PART: &str = "caustic:part";
/// The part's passes, as runs (`0-15,20`).
pub const PASS_LIST: &str = "caustic:pass_list";
/// The passes of the whole render the part belongs to.
pub const TOTAL_PASSES: &str = "caustic:total_passes";
/// Photons emitted by the part's passes.
pub const PART_PHOTONS: &str = "caustic:part_photons";
/// FNV-1a hash of the effective scene text.
pub const SCENE_HASH: &str = "caustic:scene_hash";
/// The render settings (the scene's `[render]` table as rendered).
pub const SETTINGS: &str = "caustic:settings";

/// The sum channels' quantities, in file order.
const QUANTITIES: [&str; 4] = ["R", "G", "B", "Y2"];

/// One part: the sums of some passes of one render, and what identifies the render.
#[derive(Clone, Debug)]
pub struct Part {
    /// The passes' sums.
    pub sums: PassSums,
    /// The passes of the whole render.
    pub total_passes: u32,
    /// The provenance and part keys (string attributes), sorted by key.
    pub metadata: Metadata,
}

/// Why a part file could not be read or written.
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", path.display())]
pub struct PartError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong.
    pub message: String,
}

/// Why two parts do not merge: the message names the files and what differs.
#[derive(Debug, thiserror::Error)]
#[error("{} and {}: {what}", first.display(), second.display())]
pub struct MergeError {
    /// The part merged into.
    pub first: PathBuf,
    /// The part refused.
    pub second: PathBuf,
    /// What differs.
    pub what: String,
}

/// FNV-1a (64-bit) of `text`: the scene text's fingerprint in a part.
pub fn fnv1a(text: &str) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

impl Part {
    /// A part of `sums`, one of `total_passes`, described by `provenance` (the image's
    /// metadata: [`provenance::image_metadata`]) and `settings` (the `[render]` table as TOML).
    /// Its pass count ([`provenance::PASSES`]) is the passes it holds, so `render --from` on a
    /// complete merge renders them all again.
    pub fn new(sums: PassSums, total_passes: u32, provenance: Metadata, settings: String) -> Part {
        let scene_text = provenance
            .iter()
            .find(|(k, _)| k == provenance::SCENE_TEXT)
            .map(|(_, v)| v.clone())
            .unwrap_or_default();
        let mut metadata: Metadata = provenance
            .into_iter()
            .filter(|(k, _)| k != provenance::PASSES && !k.starts_with("caustic:part") && k != PASS_LIST)
            .collect();
        metadata.extend([
            (PART.into(), "1".into()),
            (PASS_LIST.into(), passes_text(sums.passes())),
            (TOTAL_PASSES.into(), total_passes.to_string()),
            (PART_PHOTONS.into(), sums.photons().to_string()),
            (SCENE_HASH.into(), fnv1a(&scene_text)),
            (SETTINGS.into(), settings),
            (provenance::PASSES.into(), sums.passes().len().to_string()),
        ]);
        metadata.sort();
        metadata.dedup_by(|a, b| a.0 == b.0);
        Part {
            sums,
            total_passes,
            metadata,
        }
    }

    /// The value of attribute `key`.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.metadata
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// The renderer its passes were rendered with, as its settings record it (VCM or photon
    /// mapping; photon mapping when they do not say).
    pub fn renderer(&self) -> RendererKind {
        self.get(SETTINGS)
            .and_then(|text| toml::from_str::<RenderParams>(text).ok())
            .map_or(RendererKind::Ppm, |p| p.renderer)
    }

    /// Whether every pass of the render is in it.
    pub fn is_complete(&self) -> bool {
        self.sums.passes().len() as u64 == self.total_passes as u64
    }

    /// Refuses `other` (read from `theirs`) as a part of the same render as this one (read
    /// from `ours`) unless program, size, settings, scene and total passes agree and no pass is
    /// in both; the error names the first thing that differs.
    pub fn check_joins(&self, ours: &Path, other: &Part, theirs: &Path) -> Result<(), MergeError> {
        let refuse = |what: String| MergeError {
            first: ours.to_owned(),
            second: theirs.to_owned(),
            what,
        };
        let field = |p: &Part, key: &str| p.get(key).unwrap_or("(none)").to_owned();
        let software = (
            field(self, provenance::SOFTWARE),
            field(other, provenance::SOFTWARE),
        );
        if software.0 != software.1 {
            return Err(refuse(format!(
                "written by different programs: {} and {}",
                software.0, software.1
            )));
        }
        if self.sums.size() != other.sums.size() {
            let (a, b) = (self.sums.size(), other.sums.size());
            return Err(refuse(format!(
                "image sizes differ: {}x{} and {}x{}",
                a.0, a.1, b.0, b.1
            )));
        }
        let settings = (field(self, SETTINGS), field(other, SETTINGS));
        if settings.0 != settings.1 {
            return Err(refuse(format!(
                "render settings differ: {}",
                settings_difference(&settings.0, &settings.1)
            )));
        }
        let hash = (field(self, SCENE_HASH), field(other, SCENE_HASH));
        if hash.0 != hash.1 {
            return Err(refuse(format!(
                "scenes differ (scene text hash {} and {})",
                hash.0, hash.1
            )));
        }
        if self.total_passes != other.total_passes {
            return Err(refuse(format!(
                "parts of renders of different lengths: {} and {} passes",
                self.total_passes, other.total_passes
            )));
        }
        if let Some(p) = self.sums.first_shared_pass(&other.sums) {
            return Err(refuse(format!("the pass lists overlap: both hold pass {p}")));
        }
        Ok(())
    }

    /// Adds `other` (from `theirs`) to this part (from `ours`) after [`Part::check_joins`].
    pub fn merge(&mut self, ours: &Path, other: &Part, theirs: &Path) -> Result<(), MergeError> {
        self.check_joins(ours, other, theirs)?;
        self.sums.add(&other.sums).map_err(|e: SumsClash| MergeError {
            first: ours.to_owned(),
            second: theirs.to_owned(),
            what: e.to_string(),
        })?;
        self.set(PASS_LIST, passes_text(self.sums.passes()));
        self.set(PART_PHOTONS, self.sums.photons().to_string());
        self.set(provenance::PASSES, self.sums.passes().len().to_string());
        Ok(())
    }

    /// Sets attribute `key` (present in every part).
    fn set(&mut self, key: &str, value: String) {
        if let Some((_, v)) = self.metadata.iter_mut().find(|(k, _)| k == key) {
            *v = value;
        }
    }

    /// Writes the part to `path` (atomically; an existing file is replaced only with
    /// `overwrite`).
    pub fn write(&self, path: &Path, overwrite: bool) -> Result<(), PartError> {
        crate::files::write_atomically(path, overwrite, |tmp| self.write_exr(tmp)).map_err(|e| PartError {
            path: path.to_owned(),
            message: match e {
                crate::files::WriteError::Exists(_) => {
                    "the file exists; choose another name or pass --force".into()
                }
                crate::files::WriteError::Failed { message, .. } => message,
            },
        })
    }

    fn write_exr(&self, path: &Path) -> Result<(), String> {
        use exr::prelude::*;
        let (w, h) = self.sums.size();
        let mean = self.sums.mean();
        let mut list: Vec<AnyChannel<FlatSamples>> = ["R", "G", "B"]
            .iter()
            .enumerate()
            .map(|(k, name)| AnyChannel::new(*name, FlatSamples::F32(mean.iter().map(|p| p[k]).collect())))
            .collect();
        let rgb = self.sums.rgb_sums();
        let lum2 = self.sums.luminance_square_sums();
        for (q, quantity) in QUANTITIES.iter().enumerate() {
            for word in 0..4 {
                let values: Vec<u32> = (0..rgb.len())
                    .map(|i| {
                        let v = if q < 3 { rgb[i][q] } else { lum2[i] };
                        ((v as u128) >> (32 * word)) as u32
                    })
                    .collect();
                let name = format!("caustic.sum.{quantity}.w{word}");
                list.push(AnyChannel::new(name.as_str(), FlatSamples::U32(values)));
            }
        }
        let channels = AnyChannels::sort(list.into_iter().collect());
        let mut image =
            Image::from_encoded_channels((w as usize, h as usize), Encoding::FAST_LOSSLESS, channels);
        for (k, v) in &self.metadata {
            image.layer_data.attributes.other.insert(
                Text::from_slice_unchecked(k.as_bytes()),
                AttributeValue::Text(Text::from_slice_unchecked(v.as_bytes())),
            );
        }
        image.write().to_file(path).map_err(|e| e.to_string())
    }

    /// Reads a part file; the error says why it is not one (not a file, not an EXR, half
    /// written, not a part, a damaged pass list…). The header is read and checked first
    /// ([`PartHeader::read`]), so a damaged one costs nothing more.
    pub fn read(path: &Path) -> Result<Part, PartError> {
        let header = PartHeader::read(path)?;
        let error = |message: String| PartError {
            path: path.to_owned(),
            message,
        };
        let image = exr::prelude::read_first_flat_layer_from_file(path)
            .map_err(|e| error(format!("not a readable EXR image (half written?): {e}")))?;
        let layer = &image.layer_data;
        let (w, h) = header.size;
        if (layer.size.0, layer.size.1) != (w as usize, h as usize) {
            return Err(error("it changed while it was read".into()));
        }
        let (rgb, lum2) = read_sums(&layer.channel_data, layer.size.0 * layer.size.1).map_err(error)?;
        let sums = PassSums::from_parts((w, h), rgb, lum2, header.passes, header.photons)
            .ok_or_else(|| error("its sums do not match its size".into()))?;
        Ok(Part {
            sums,
            total_passes: header.total_passes,
            metadata: header.metadata,
        })
    }
}

/// A part file's header, read without its pixels: the render it belongs to ([`RenderKey`]),
/// the passes it holds and its size. What `render --from PART` and a watched folder need
/// before deciding to read the sums.
#[derive(Clone, Debug, PartialEq)]
pub struct PartHeader {
    /// The provenance and part keys (string attributes), sorted by key.
    pub metadata: Metadata,
    /// The passes it holds, ascending.
    pub passes: Vec<u32>,
    /// The passes of the whole render.
    pub total_passes: u32,
    /// Photons its passes emitted.
    pub photons: u64,
    /// Image width and height.
    pub size: (u32, u32),
    /// The render it belongs to.
    pub key: RenderKey,
}

/// What makes parts parts of one render: they merge only when all of it agrees.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct RenderKey {
    /// The program that wrote it.
    pub software: String,
    /// Image width and height.
    pub size: (u32, u32),
    /// The render settings.
    pub settings: String,
    /// The scene text's hash.
    pub scene_hash: String,
    /// The passes of the whole render.
    pub total_passes: u32,
}

impl PartHeader {
    /// Reads and checks the header of the part file at `path`.
    pub fn read(path: &Path) -> Result<PartHeader, PartError> {
        let error = |message: String| PartError {
            path: path.to_owned(),
            message,
        };
        let file = crate::input_file::open(path).map_err(|why| error(format!("the file {why}")))?;
        Self::parse(std::io::BufReader::new(file)).map_err(error)
    }

    /// Reads and checks a part file's header from `reader` (the start of the file).
    pub fn parse(reader: impl std::io::Read) -> Result<PartHeader, String> {
        let meta = exr::meta::MetaData::read_from_buffered(reader, false)
            .map_err(|e| format!("not a readable EXR image (half written?): {e}"))?;
        let header = meta.headers.first().ok_or("the EXR file holds no image")?;
        let mut metadata = exr_text_attributes(
            header
                .own_attributes
                .other
                .iter()
                .chain(header.shared_attributes.other.iter()),
        );
        metadata.sort();
        metadata.dedup_by(|a, b| a.0 == b.0);
        let get = |key: &str| metadata.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str());
        match get(PART) {
            Some("1") => {}
            None => {
                return Err("not a part file (no caustic:part attribute: render it with --shard K/N)".into())
            }
            Some(v) => {
                return Err(format!(
                    "its {PART} is {v:?}: a part file of another format (this program reads format 1)"
                ))
            }
        }
        let total_passes = get(TOTAL_PASSES)
            .and_then(|v| v.parse::<u32>().ok())
            .ok_or_else(|| format!("its {TOTAL_PASSES} is missing or not a number"))?;
        crate::settings::limits::passes(total_passes).map_err(|e| format!("its {TOTAL_PASSES} {e}"))?;
        let passes = parse_passes(
            get(PASS_LIST).ok_or_else(|| format!("its {PASS_LIST} is missing"))?,
            total_passes,
        )
        .map_err(|e| format!("its {PASS_LIST} is damaged: {e}"))?;
        let photons = get(PART_PHOTONS)
            .and_then(|v| v.parse::<u64>().ok())
            .ok_or_else(|| format!("its {PART_PHOTONS} is missing or not a number"))?;
        let (w, h) = (header.layer_size.0, header.layer_size.1);
        let side = |v: usize| {
            u32::try_from(v)
                .ok()
                .and_then(|v| crate::settings::limits::image_side(v).ok())
        };
        let (Some(w), Some(h)) = (side(w), side(h)) else {
            return Err(format!(
                "its image is {w}x{h} pixels; a part's sides are 1 to {} pixels",
                crate::settings::limits::IMAGE_SIDE.end()
            ));
        };
        let field = |key: &str| get(key).unwrap_or("(none)").to_owned();
        let key = RenderKey {
            software: field(provenance::SOFTWARE),
            size: (w, h),
            settings: field(SETTINGS),
            scene_hash: field(SCENE_HASH),
            total_passes,
        };
        Ok(PartHeader {
            passes,
            total_passes,
            photons,
            size: (w, h),
            key,
            metadata,
        })
    }

    /// The value of attribute `key`.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.metadata
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// The fixed-point sums in a part's `caustic.sum.*` channels, `n` pixels each: Σ RGB and
/// Σ luminance²; the error names a missing or malformed channel.
fn read_sums(
    channels: &exr::prelude::AnyChannels<exr::prelude::FlatSamples>,
    n: usize,
) -> Result<(Vec<[i128; 3]>, Vec<i128>), String> {
    let channel = |name: &str| -> Result<&Vec<u32>, String> {
        let c = channels
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .ok_or_else(|| format!("channel {name} is missing"))?;
        match &c.sample_data {
            exr::prelude::FlatSamples::U32(v) if v.len() == n => Ok(v),
            _ => Err(format!("channel {name} is not {n} u32 samples")),
        }
    };
    let mut quantities: Vec<Vec<i128>> = Vec::with_capacity(4);
    for quantity in QUANTITIES {
        let words: Vec<&Vec<u32>> = (0..4)
            .map(|w| channel(&format!("caustic.sum.{quantity}.w{w}")))
            .collect::<Result<_, _>>()?;
        let word = |i: usize| (0..4).fold(0u128, |acc, w| acc | (words[w][i] as u128) << (32 * w)) as i128;
        quantities.push((0..n).map(word).collect());
    }
    let lum2 = quantities.pop().unwrap_or_default();
    let rgb = (0..n)
        .map(|i| [quantities[0][i], quantities[1][i], quantities[2][i]])
        .collect();
    Ok((rgb, lum2))
}

/// What differs between two `[render]` tables: the first keys whose lines differ.
pub(super) fn settings_difference(a: &str, b: &str) -> String {
    let lines = |t: &str| -> Vec<(String, String)> {
        t.lines()
            .filter_map(|l| l.split_once('='))
            .map(|(k, v)| (k.trim().to_owned(), v.trim().to_owned()))
            .collect()
    };
    let (la, lb) = (lines(a), lines(b));
    let mut keys: Vec<&String> = la.iter().chain(&lb).map(|(k, _)| k).collect();
    keys.sort();
    keys.dedup();
    let value = |l: &[(String, String)], k: &str| {
        l.iter()
            .find(|(key, _)| key == k)
            .map_or("(unset)".to_owned(), |(_, v)| v.clone())
    };
    let diffs: Vec<String> = keys
        .into_iter()
        .filter(|k| value(&la, k) != value(&lb, k))
        .map(|k| format!("{k} {} and {}", value(&la, k), value(&lb, k)))
        .collect();
    if diffs.is_empty() {
        "(in form only)".into()
    } else {
        diffs.join(", ")
    }
}
