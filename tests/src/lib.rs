//! Helpers shared by the workspace integration tests: finding QEMU and the Cortex-M
//! target, building the firmware binaries (a `cargo build` subprocess with its own
//! target directory), and running them under `qemu-system-arm -machine mps2-an386`
//! with semihosting and a hard timeout.
//!
//! Missing tools skip the QEMU tests loudly (a banner on stderr) unless the environment
//! sets `FOG_REQUIRE_QEMU=1`, in which case they fail: CI sets it, a laptop without QEMU
//! still runs every host test.

pub mod console;

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

/// The firmware's target triple.
pub const FW_TARGET: &str = "thumbv7em-none-eabihf";
/// Cargo profile of firmware builds (release, optimised for size; root Cargo.toml).
pub const FW_PROFILE: &str = "fw";
/// QEMU machine: MPS2 AN386, Cortex-M4F, 25 MHz core clock.
pub const QEMU_MACHINE: &str = "mps2-an386";

/// Workspace root (the parent of this crate).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ has a parent")
        .to_path_buf()
}

/// True if the environment demands the QEMU scenarios (CI).
pub fn qemu_required() -> bool {
    std::env::var("FOG_REQUIRE_QEMU").is_ok_and(|v| v == "1")
}

/// Why a QEMU scenario cannot run here, if it cannot.
pub fn missing_tool() -> Option<String> {
    let qemu = Command::new("qemu-system-arm")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
    if !qemu.is_ok_and(|s| s.success()) {
        return Some("qemu-system-arm not found (apt-get install qemu-system-arm)".into());
    }
    let sysroot = Command::new(rustc())
        .args(["--print", "sysroot"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| PathBuf::from(String::from_utf8_lossy(&o.stdout).trim()));
    match sysroot {
        Some(root) if root.join("lib/rustlib").join(FW_TARGET).is_dir() => None,
        _ => Some(format!(
            "Rust target {FW_TARGET} not installed (rustup target add {FW_TARGET})"
        )),
    }
}

/// `true` if the QEMU scenario `name` can run. Otherwise prints a loud banner and
/// returns `false` (the test then returns early), or panics under FOG_REQUIRE_QEMU=1.
pub fn qemu_ready(name: &str) -> bool {
    let Some(why) = missing_tool() else {
        return true;
    };
    assert!(!qemu_required(), "{name}: FOG_REQUIRE_QEMU=1 but {why}");
    eprintln!("\n**********************************************************************");
    eprintln!("** SKIPPING QEMU SCENARIO `{name}`: {why}");
    eprintln!("** (set FOG_REQUIRE_QEMU=1 to make this a failure)");
    eprintln!("**********************************************************************\n");
    false
}

fn rustc() -> String {
    std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into())
}

fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".into())
}

/// Where the firmware subprocess build puts its artefacts: `FOG_FW_TARGET_DIR`, else
/// `$CARGO_TARGET_DIR/fw`, else `<workspace>/target/fw`. A separate directory keeps the
/// firmware build from contending for the host build's lock.
pub fn firmware_target_dir() -> PathBuf {
    if let Ok(dir) = std::env::var("FOG_FW_TARGET_DIR") {
        return PathBuf::from(dir);
    }
    match std::env::var("CARGO_TARGET_DIR") {
        Ok(dir) => PathBuf::from(dir).join("fw"),
        Err(_) => workspace_root().join("target").join("fw"),
    }
}

/// Build every firmware binary (profile `fw`, semihosting logs) once per test process and
/// return the directory holding the ELFs. Concurrent test processes serialise on
/// cargo's own lock of the target directory.
pub fn build_firmware() -> Result<PathBuf, String> {
    static BUILT: OnceLock<Mutex<Option<Result<PathBuf, String>>>> = OnceLock::new();
    build_target_once(
        &BUILT,
        &[
            "-p",
            "fog-firmware",
            "--bins",
            "--features",
            "log-semihosting,test-key",
        ],
    )
}

/// Build the STM32F407 board binary (`board-f407/`, profile `fw`, TEST key: the CI
/// build) once per test process; returns the path of its ELF.
pub fn build_board_elf() -> Result<PathBuf, String> {
    static BUILT: OnceLock<Mutex<Option<Result<PathBuf, String>>>> = OnceLock::new();
    build_target_once(&BUILT, &["-p", "fog-board-f407", "--features", "test-key"])
        .map(|dir| dir.join("f407-app"))
}

/// `cargo build --profile fw --target FW_TARGET <args>` into `firmware_target_dir()`,
/// once per `cell`; the directory holding the artefacts.
fn build_target_once(
    cell: &OnceLock<Mutex<Option<Result<PathBuf, String>>>>,
    args: &[&str],
) -> Result<PathBuf, String> {
    let cell = cell.get_or_init(|| Mutex::new(None));
    let mut guard = cell.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(done) = guard.as_ref() {
        return done.clone();
    }
    let target_dir = firmware_target_dir();
    let out = Command::new(cargo())
        .current_dir(workspace_root())
        .args(["build", "--profile", FW_PROFILE, "--target", FW_TARGET])
        .args(args)
        .arg("--target-dir")
        .arg(&target_dir)
        .env_remove("CARGO_TARGET_DIR")
        .output()
        .map_err(|e| format!("cannot run cargo: {e}"));
    let result = out.and_then(|o| {
        if o.status.success() {
            Ok(target_dir.join(FW_TARGET).join(FW_PROFILE))
        } else {
            Err(format!(
                "firmware build {args:?} failed ({}):\n{}",
                o.status,
                String::from_utf8_lossy(&o.stderr)
            ))
        }
    });
    *guard = Some(result.clone());
    result
}

/// A count from the environment (`FOG_PROBE_*`: the probes' full runs), else `default`;
/// a value that is not a count stops the test with its name.
pub fn env_count(var: &str, default: u64) -> u64 {
    std::env::var(var).ok().map_or(default, |s| {
        s.parse()
            .unwrap_or_else(|_| panic!("{var}={s}: not a count"))
    })
}

/// Path of one firmware ELF (building first if needed).
pub fn firmware_elf(bin: &str) -> PathBuf {
    match build_firmware() {
        Ok(dir) => dir.join(bin),
        Err(e) => panic!("{e}"),
    }
}

/// How to run one QEMU instance.
#[derive(Clone, Debug, Default)]
pub struct QemuOptions {
    /// Program arguments seen by the firmware (semihosting `args`), after argv[0].
    pub args: Vec<String>,
    /// `-icount shift=0`: one instruction = 1 ns of virtual time (deterministic counts).
    pub icount: bool,
    /// Extra raw QEMU arguments (e.g. `-serial tcp:...`).
    pub extra: Vec<String>,
    /// Working directory (semihosting file paths are relative to it).
    pub cwd: Option<PathBuf>,
    /// QEMU machine (`None`: `QEMU_MACHINE`, mps2-an386).
    pub machine: Option<&'static str>,
}

/// The QEMU command line for `elf`.
pub fn qemu_command(elf: &Path, opts: &QemuOptions) -> Command {
    let mut semi = String::from("enable=on,target=native");
    let argv0 = elf.file_name().map(|n| n.to_string_lossy().into_owned());
    for a in argv0.iter().chain(&opts.args) {
        assert!(!a.contains(','), "semihosting arguments cannot contain ','");
        semi.push_str(",arg=");
        semi.push_str(a);
    }
    let mut cmd = Command::new("qemu-system-arm");
    let machine = opts.machine.unwrap_or(QEMU_MACHINE);
    cmd.args(["-machine", machine, "-cpu", "cortex-m4", "-nographic"])
        .args(["-monitor", "none"])
        .args(["-semihosting-config", &semi]);
    if opts.icount {
        cmd.args(["-icount", "shift=0"]);
    }
    if !opts.extra.iter().any(|a| a == "-serial") {
        cmd.args(["-serial", "null"]);
    }
    cmd.args(&opts.extra).arg("-kernel").arg(elf);
    if let Some(dir) = &opts.cwd {
        cmd.current_dir(dir);
    }
    cmd
}

/// Kills the child when dropped (a failing test never leaves QEMU running).
pub struct KillOnDrop(pub Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Start QEMU in the background (stdout/stderr piped), killed when the guard drops.
pub fn spawn_qemu(elf: &Path, opts: &QemuOptions) -> std::io::Result<KillOnDrop> {
    qemu_command(elf, opts)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map(KillOnDrop)
}

/// Result of a finished QEMU run.
#[derive(Debug)]
pub struct QemuRun {
    pub status: ExitStatus,
    pub stdout: Vec<u8>,
    pub stderr: String,
    pub wall: Duration,
}

/// Run `elf` to completion (semihosting exit), or fail after `timeout`.
pub fn run_qemu(elf: &Path, opts: &QemuOptions, timeout: Duration) -> Result<QemuRun, String> {
    let start = Instant::now();
    let mut guard = spawn_qemu(elf, opts).map_err(|e| format!("cannot start QEMU: {e}"))?;
    let child = &mut guard.0;
    // Drain the pipes on threads so a chatty firmware cannot block on a full pipe.
    let mut out_pipe = child.stdout.take().expect("piped");
    let mut err_pipe = child.stderr.take().expect("piped");
    let out_t = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = out_pipe.read_to_end(&mut v);
        v
    });
    let err_t = std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = err_pipe.read_to_end(&mut v);
        v
    });
    let status = loop {
        match child.try_wait() {
            Ok(Some(s)) => break s,
            Ok(None) if start.elapsed() > timeout => {
                return Err(format!("QEMU did not finish within {timeout:?}: killed"));
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(20)),
            Err(e) => return Err(format!("waiting for QEMU: {e}")),
        }
    };
    Ok(QemuRun {
        status,
        stdout: out_t.join().unwrap_or_default(),
        stderr: String::from_utf8_lossy(&err_t.join().unwrap_or_default()).into_owned(),
        wall: start.elapsed(),
    })
}

/// A fresh scratch directory under the firmware target dir, for input/output files.
pub fn scratch_dir(name: &str) -> PathBuf {
    let dir = firmware_target_dir()
        .join("scratch")
        .join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}

/// Size of the linked firmware sections (llvm-size, Berkeley format).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FirmwareSize {
    /// .text + .rodata + .vector_table + .data initialisers: bytes of flash.
    pub flash: u64,
    /// .data + .bss (+ .uninit): static RAM, bytes (the stack is not included).
    pub static_ram: u64,
}

/// One allocated section of an ELF: name, size and address (bytes).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Section {
    pub name: String,
    pub size: u64,
    pub addr: u64,
}

/// The sections of `elf` (`llvm-size -A`, sysV format: one per line).
pub fn elf_sections(elf: &Path) -> Result<Vec<Section>, String> {
    let tool = llvm_tool("llvm-size")?;
    let out = Command::new(&tool)
        .arg("-A")
        .arg(elf)
        .output()
        .map_err(|e| format!("{}: {e}", tool.display()))?;
    if !out.status.success() {
        return Err(String::from_utf8_lossy(&out.stderr).into_owned());
    }
    Ok(String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|line| {
            let mut it = line.split_whitespace();
            let name = it.next()?.to_string();
            let size = it.next()?.parse().ok()?;
            let addr = it.next()?.parse().ok()?;
            Some(Section { name, size, addr })
        })
        .collect())
}

/// Measure an ELF's flash and static RAM with `llvm-size -A` (sysV: per section).
pub fn firmware_size(elf: &Path) -> Result<FirmwareSize, String> {
    let mut size = FirmwareSize {
        flash: 0,
        static_ram: 0,
    };
    for s in elf_sections(elf)? {
        match s.name.as_str() {
            ".vector_table" | ".text" | ".rodata" => size.flash += s.size,
            ".data" => {
                size.flash += s.size;
                size.static_ram += s.size;
            }
            ".bss" | ".uninit" => size.static_ram += s.size,
            _ => {}
        }
    }
    Ok(size)
}

/// An LLVM binutil: from PATH, else from the Rust toolchain's `llvm-tools` component.
pub fn llvm_tool(name: &str) -> Result<PathBuf, String> {
    if Command::new(name)
        .arg("--version")
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
    {
        return Ok(PathBuf::from(name));
    }
    let out = Command::new(rustc())
        .args(["--print", "sysroot"])
        .output()
        .map_err(|e| format!("rustc: {e}"))?;
    let root = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    let host = Command::new(rustc())
        .arg("-vV")
        .output()
        .ok()
        .and_then(|o| {
            String::from_utf8_lossy(&o.stdout)
                .lines()
                .find_map(|l| l.strip_prefix("host: ").map(str::to_owned))
        })
        .ok_or("rustc -vV has no host line")?;
    let p = root.join("lib/rustlib").join(host).join("bin").join(name);
    if p.is_file() {
        Ok(p)
    } else {
        Err(format!(
            "{name} not found on PATH nor in the toolchain (rustup component add llvm-tools)"
        ))
    }
}

/// A loopback TCP port nobody listens on right now (for QEMU's `-serial tcp:...,server`).
pub fn free_loopback_port() -> u16 {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").expect("bind loopback");
    listener.local_addr().expect("local addr").port()
}

/// Connects to QEMU's serial server on `port`, retrying until it listens (bounded).
pub fn connect_loopback(port: u16, within: Duration) -> std::net::TcpStream {
    let start = Instant::now();
    loop {
        match std::net::TcpStream::connect(("127.0.0.1", port)) {
            Ok(stream) => return stream,
            Err(e) if start.elapsed() > within => {
                panic!(
                    "QEMU serial server on 127.0.0.1:{port} not reachable within {within:?}: {e}"
                )
            }
            Err(_) => std::thread::sleep(Duration::from_millis(50)),
        }
    }
}
