//! The machine's memory as the speed suite reports it: the rate at which one or more threads
//! fill memory (the last-level cache's size beside it is the library's,
//! `tessera::engine::last_level_cache_bytes`). A uniform frame writes its output once, so
//! once the output is larger than the cache its speed is bounded by that fill rate; the
//! rows give their output bytes per second as a share of it, which says how far a frame is
//! from memory speed on *this* machine (whose cache may hold a whole frame, or not).

use rayon::prelude::*;
use std::time::Instant;

/// Memory fill bandwidth in GB/s (10⁹ bytes a second) with the threads of the current rayon
/// pool: the median of `runs` timed fills of a `bytes` buffer (`slice::fill`, that is
/// `memset`, each thread filling one contiguous share), after one untimed fill that maps
/// the pages. Choose `bytes` well above the L3 size, or this measures the cache.
/// Cost: `bytes` of memory for the call and `runs + 1` fills.
pub fn fill_bandwidth(bytes: usize, runs: usize) -> f64 {
    let mut buffer = vec![0u8; bytes];
    let share = bytes.div_ceil(rayon::current_num_threads()).max(1);
    let mut fill = |value: u8| buffer.par_chunks_mut(share).for_each(|c| c.fill(value));
    fill(1);
    let mut rates: Vec<f64> = (0..runs.max(1))
        .map(|r| {
            let start = Instant::now();
            fill(r as u8);
            bytes as f64 / start.elapsed().as_secs_f64() / 1e9
        })
        .collect();
    std::hint::black_box(&buffer);
    rates.sort_by(f64::total_cmp);
    rates[rates.len() / 2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fill_has_a_finite_positive_rate() {
        let rate = fill_bandwidth(1 << 20, 3);
        assert!(rate.is_finite() && rate > 0.0, "{rate}");
    }
}
