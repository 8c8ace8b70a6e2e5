//! Helpers the tests share across the crate (the unit tests, the integration tests, the
//! fuzz checks and tessera-gpu's tests): where the test models are, parse-error assertions,
//! and one seeded pseudo-random generator, so that every test's sequence comes from the same
//! definition. Not part of the public API; compiled for tests and under the `fuzzing`
//! feature only.

use std::fmt::Debug;
use std::path::{Path, PathBuf};

use crate::error::{Error, Location, Result};

/// Path of a test model, relative to the shared data folder: `$TESSERA_DATA`, else
/// `../shared/data` beside the checkout (as the integration tests find it).
pub fn data(rel: &str) -> PathBuf {
    let dir = std::env::var_os("TESSERA_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    dir.join(rel)
}

/// The files of the shared data's folder `folder` whose names start with one of `prefixes`,
/// sorted. Panics, naming the folder, where it cannot be read.
pub fn data_files(folder: &str, prefixes: &[&str]) -> Vec<PathBuf> {
    let dir = data(folder);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e} (set TESSERA_DATA)", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name().is_some_and(|n| prefixes.iter().any(|s| n.to_string_lossy().starts_with(s)))
        })
        .collect();
    files.sort();
    files
}

/// Asserts that `result` is a parse error at `file:line` whose message names the file
/// and contains `needle`.
#[track_caller]
pub fn assert_parse_error<T: Debug>(result: Result<T>, file: &str, line: usize, needle: &str) {
    let err = match result {
        Ok(v) => panic!("expected an error containing {needle:?}, got {v:?}"),
        Err(e) => e,
    };
    let msg = err.to_string();
    match &err {
        Error::Parse { at: Location { file: f, line: l }, .. } => {
            assert_eq!(f, Path::new(file), "{msg}");
            assert_eq!(*l, line, "{msg}");
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    assert!(msg.contains(file), "{msg}");
    assert!(msg.contains(needle), "{msg:?} lacks {needle:?}");
}

/// Tiny LCG (Knuth's MMIX constants) so the property loops need no extra dependency; the
/// state is the seed, public so a test can start from any.
pub struct Lcg(pub u64);

impl Lcg {
    /// Advances the state one step and returns it whole.
    fn step(&mut self) -> u64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        self.0
    }

    /// The next 31 pseudo-random bits (the state's top 31).
    // Not an `Iterator`: the stream never ends, and the tests (tessera-gpu's too) call it by
    // this name.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> u32 {
        (self.step() >> 33) as u32
    }

    /// A pseudo-random number in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        self.next() as usize % n
    }

    /// A pseudo-random number in `[0, 1)` from 31 bits.
    pub fn unit(&mut self) -> f64 {
        self.next() as f64 / (1u64 << 31) as f64
    }

    /// A pseudo-random number in `[0, 1)` from 53 bits (the state's top 53, every bit an
    /// `f64` in that range can hold).
    pub fn unit53(&mut self) -> f64 {
        (self.step() >> 11) as f64 / (1u64 << 53) as f64
    }
}
