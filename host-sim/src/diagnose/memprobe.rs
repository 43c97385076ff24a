//! Where `diagnose` peaks in memory, stage by stage (issue 18 item 8): with
//! `FOG_DIAG_MEM_PROBE=1` in the environment, each [`stage`] call prints the process's
//! peak resident set since the previous call (`VmHWM` of `/proc/self/status`, Linux) to
//! stderr and resets it (`5` written to `/proc/self/clear_refs`). Without the variable,
//! or off Linux, it does nothing. Only stderr is written: reports are unchanged.

use std::sync::OnceLock;

/// The environment variable that turns the probe on.
pub const ENV: &str = "FOG_DIAG_MEM_PROBE";

fn enabled() -> bool {
    static ON: OnceLock<bool> = OnceLock::new();
    *ON.get_or_init(|| std::env::var_os(ENV).is_some_and(|v| v == "1"))
}

/// Reports the peak RSS since the last call as the peak of `name`, then resets it.
pub fn stage(name: &str) {
    if !enabled() {
        return;
    }
    let peak_kb = std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("VmHWM:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        });
    match peak_kb {
        Some(kb) => eprintln!("mem-probe: {name}: peak {kb} KB"),
        None => eprintln!("mem-probe: {name}: VmHWM not readable"),
    }
    // Best effort: where clear_refs is not writable the next peak includes this one.
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}
