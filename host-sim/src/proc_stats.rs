//! What this process has used so far, read from `/proc` (Linux; zero elsewhere): CPU time
//! and peak resident memory, for the summary's per-stage figures.

/// CPU time (user + system, all threads) of this process so far, seconds, from
/// `/proc/self/stat` (Linux; 0 elsewhere). On a shared machine wall time says little; CPU
/// time per stage says where the work goes.
pub fn process_cpu_s() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let Some(rest) = stat.rsplit(')').next() else {
        return 0.0;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    // rest starts at field 3 (state): field k is f[k - 3]. Linux clock ticks are 100 Hz.
    (ticks(11) + ticks(12)) / 100.0
}

/// Peak resident memory of this process so far (VmHWM of `/proc/self/status`), bytes; 0
/// where unavailable.
pub fn peak_rss_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|v| v.parse::<u64>().ok())
        })
        .map_or(0, |kb| kb * 1024)
}
