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

/// CPU time of the calling thread so far, seconds (`/proc/thread-self/schedstat`, in
/// nanoseconds; 0 where unavailable).
pub fn thread_cpu_s() -> f64 {
    schedstat_s("/proc/thread-self/schedstat")
}

/// CPU time so far of this process's live threads whose name starts with `prefix`,
/// seconds (`/proc/self/task/*/comm` and `schedstat`; 0 where unavailable). Threads that
/// have ended are not counted: read it while they run.
pub fn named_threads_cpu_s(prefix: &str) -> f64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else {
        return 0.0;
    };
    tasks
        .flatten()
        .filter(|t| {
            std::fs::read_to_string(t.path().join("comm"))
                .is_ok_and(|c| c.trim_end().starts_with(prefix))
        })
        .map(|t| schedstat_s(&t.path().join("schedstat").to_string_lossy()))
        .sum()
}

/// The first field of a `schedstat` file (time on a CPU, ns) in seconds.
fn schedstat_s(path: &str) -> f64 {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .map_or(0.0, |ns| ns as f64 * 1e-9)
}
