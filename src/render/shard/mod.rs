//! Rendering in independent passes, split across processes or machines: which passes a
//! shard renders ([`Shard`]), their exact sums ([`PassSums`]), the part file a shard writes and
//! the merge of parts ([`part`]) and of a folder's parts as they land ([`folder`]).
//!
//! With the global radius schedule (Knaus & Zwicker 2011, "Progressive photon mapping: a
//! probabilistic approach"; [`crate::settings::RadiusSchedule::Global`]) every pass `i` is an
//! independent estimate whose random streams derive from (scene seed, `i`) alone, so shard
//! `K` of `N` renders the passes `i ≡ K (mod N)` and the image is the sum of every shard's
//! sums over the number of passes. Sums are kept in fixed point ([`sums`]), so adding them
//! in any order gives the same bits: `N` merged shards equal one process, bit for bit.

pub mod folder;
pub mod part;
pub mod render_part;
pub mod sums;

pub use folder::{FolderMerge, RenderInFolder, ScanReport};
pub use part::{MergeError, Part, PartError, PartHeader, RenderKey};
pub use render_part::{merge_parts, shard_part};
pub use sums::PassSums;

/// Which of a render's passes one process renders: pass `i` when `i mod count == index`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// K, in `0..count`.
    pub index: u32,
    /// N, at least 1.
    pub count: u32,
}

impl Default for Shard {
    /// The whole render in one process.
    fn default() -> Self {
        Self { index: 0, count: 1 }
    }
}

impl Shard {
    /// Parses `K/N` (as `--shard` takes it), with `0 ≤ K < N`.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let (k, n) = text
            .split_once('/')
            .ok_or_else(|| format!("expected K/N (such as 0/4), got {text:?}"))?;
        let number = |s: &str, what: &str| {
            s.trim()
                .parse::<u32>()
                .map_err(|_| format!("{what} must be a whole number, got {s:?} in {text:?}"))
        };
        let (index, count) = (number(k, "K")?, number(n, "N")?);
        if count == 0 {
            return Err(format!("N must be at least 1, got {text:?}"));
        }
        if index >= count {
            return Err(format!("K must be below N (0 to {}), got {text:?}", count - 1));
        }
        Ok(Shard { index, count })
    }

    /// Its `j`-th pass (`K + j·N`).
    pub fn pass(self, j: u32) -> u64 {
        self.index as u64 + j as u64 * self.count as u64
    }

    /// How many of the passes `0..total` are its own.
    pub fn passes_of(self, total: u32) -> u32 {
        if self.index >= total {
            0
        } else {
            (total - self.index).div_ceil(self.count)
        }
    }
}

/// The passes of a render one process renders: a shard's, or a list of them (a part's own,
/// which `render --from PART` renders again).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PassSet {
    /// Pass `i` when `i mod N = K`.
    Shard(Shard),
    /// These passes, ascending and distinct.
    List(std::sync::Arc<[u32]>),
}

impl Default for PassSet {
    /// Every pass.
    fn default() -> Self {
        PassSet::Shard(Shard::default())
    }
}

impl PassSet {
    /// Its `j`-th pass.
    pub fn pass(&self, j: u32) -> u64 {
        match self {
            PassSet::Shard(s) => s.pass(j),
            PassSet::List(l) => l.get(j as usize).map_or(u64::MAX, |&p| p as u64),
        }
    }

    /// How many of the passes `0..total` are its own.
    pub fn passes_of(&self, total: u32) -> u32 {
        match self {
            PassSet::Shard(s) => s.passes_of(total),
            PassSet::List(l) => l.iter().take_while(|&&p| p < total).count() as u32,
        }
    }
}

impl std::fmt::Display for PassSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PassSet::Shard(s) => write!(f, "{s}"),
            PassSet::List(l) => write!(f, "passes {}", sums::passes_text(l)),
        }
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_split_the_passes_without_overlap() {
        for n in 1..6u32 {
            for total in [1u32, 7, 10, 64] {
                let mut seen = vec![0; total as usize];
                for k in 0..n {
                    let s = Shard { index: k, count: n };
                    for j in 0..s.passes_of(total) {
                        seen[s.pass(j) as usize] += 1;
                    }
                }
                assert!(seen.iter().all(|&c| c == 1), "{n} shards of {total}: {seen:?}");
            }
        }
    }

    #[test]
    fn parse_names_what_is_wrong() {
        assert_eq!(Shard::parse("2/4"), Ok(Shard { index: 2, count: 4 }));
        assert!(Shard::parse("4/4")
            .expect_err("refused")
            .contains("K must be below N"));
        assert!(Shard::parse("0/0")
            .expect_err("refused")
            .contains("N must be at least 1"));
        assert!(Shard::parse("x/2").expect_err("refused").contains("whole number"));
        assert!(Shard::parse("3").expect_err("refused").contains("expected K/N"));
    }
}
