//! Where the MCU image's instructions go: a profile by function of whole control periods,
//! from QEMU's own instruction trace.
//!
//! For a window of sensor frames, QEMU is switched (over its monitor) to translate one
//! instruction per block (`singlestep on`) and to log every block it executes
//! (`log exec,nochain`): each line of the log is then one executed instruction with its
//! address. The image marks its measured work with two functions that are never inlined
//! ([`WORK_START`] and [`WORK_END`], `firmware/src/mcu/budget.rs`): only the instructions
//! between the entry of the first and the entry of the second count, the same work the
//! image's own SysTick figures (`CYC_MEAN`) charge to its control periods; the idle loop's
//! polling between frames is left out. Each instruction is charged to the function whose
//! symbol covers its address (code inlined into a function is that function's).
//!
//! The window opens just before its first frame is sent and closes once the last frame's work
//! is logged (the log has stopped growing), with the image idle at both ends: a window of
//! `2 N` frames at 100 Hz is `N` whole 20 ms control periods.

use nix::sys::stat::Mode;
use object::{Object, ObjectSymbol, SymbolKind};
use serde::Serialize;
use std::collections::HashMap;
use std::io::{self, BufRead, Read, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Symbol of the function whose entry starts the measured work of a pass.
pub const WORK_START: &str = "budget_work_start";
/// Symbol of the function whose entry ends it.
pub const WORK_END: &str = "budget_work_end";

/// Sensor frames per 20 ms control period (100 Hz frames).
const FRAMES_PER_PERIOD: u64 = 2;

/// Which control periods to profile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ProfileWindow {
    /// Sensor frame (counted from the first, 100 Hz) before which the window opens.
    pub start_frame: u64,
    /// Whole control periods in the window.
    pub periods: u32,
}

impl ProfileWindow {
    /// Parses `SECONDS[:PERIODS]` (simulated seconds from the first sensor frame; 10 periods
    /// by default).
    pub fn parse(s: &str) -> Result<Self, String> {
        let (at, n) = match s.split_once(':') {
            Some((a, n)) => (a, Some(n)),
            None => (s, None),
        };
        let at: f64 = at
            .trim()
            .parse()
            .map_err(|_| format!("profile `{s}`: `{at}` is not a time in seconds"))?;
        if !(at.is_finite() && at >= 0.0) {
            return Err(format!("profile `{s}`: the time must be 0 s or later"));
        }
        let periods = match n {
            Some(n) => n
                .trim()
                .parse::<u32>()
                .ok()
                .filter(|p| (1..=500).contains(p))
                .ok_or_else(|| format!("profile `{s}`: `{n}` periods: expected 1 to 500"))?,
            None => 10,
        };
        Ok(Self {
            start_frame: (at * 100.0).round() as u64,
            periods,
        })
    }

    fn end_frame(&self) -> u64 {
        self.start_frame + FRAMES_PER_PERIOD * u64::from(self.periods)
    }
}

/// The instructions of one function in the window.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FunctionCost {
    /// The function, demangled, without its hash.
    pub function: String,
    /// Instructions per control period, on average over the window.
    pub instr_per_period: f64,
    /// Share of the window's measured instructions, percent.
    pub percent: f64,
}

/// A profile of whole control periods: the `mcu.profile` object of
/// `sim-host fly --link qemu --profile ... --json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct McuProfile {
    /// Sensor frame before which the window opened.
    pub start_frame: u64,
    /// Control periods in the window.
    pub periods: u32,
    /// Measured instructions per control period, on average over the window.
    pub instr_per_period: f64,
    /// Every function that ran, costliest first.
    pub functions: Vec<FunctionCost>,
    /// The window's costliest pass of work (from one wake of the image to its return to
    /// waiting), by function: where a single heavy tick spends what the averages spread.
    pub costliest_pass: Option<PassCost>,
}

/// One pass of the image's work, by function.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PassCost {
    /// Which pass of the window, from 0.
    pub index: u64,
    /// Its instructions.
    pub instructions: u64,
    /// Every function that ran in it, costliest first (`instr_per_period` here: in the pass).
    pub functions: Vec<FunctionCost>,
    /// The memory routines' instructions (`memcpy`, `memcmp`, `memset` and their `__aeabi_`
    /// entries), charged to the function that called them, costliest first.
    pub memory_callers: Vec<FunctionCost>,
}

impl McuProfile {
    /// The `n` costliest functions as a Markdown table.
    pub fn markdown(&self, n: usize) -> String {
        let mut s = format!(
            "{} control periods from sensor frame {}: {:.0} instructions per period.\n\n\
             | function | instructions per period | share |\n|---|---:|---:|\n",
            self.periods, self.start_frame, self.instr_per_period
        );
        push_rows(&mut s, &self.functions, n, Some(self.instr_per_period));
        if let Some(c) = &self.costliest_pass {
            s.push_str(&format!(
                "\nThe costliest pass of work, pass {} of the window: {} instructions.\n\n\
                 | function | instructions | share |\n|---|---:|---:|\n",
                c.index, c.instructions
            ));
            push_rows(&mut s, &c.functions, n, Some(c.instructions as f64));
            s.push_str(
                "\nIts memory routines by caller:\n\n\
                 | caller | instructions | share of the pass |\n|---|---:|---:|\n",
            );
            push_rows(&mut s, &c.memory_callers, n, None);
        }
        s
    }
}

/// The rows of the `n` costliest of `functions`, then, with the `total` instructions they
/// share, one row for the rest.
fn push_rows(s: &mut String, functions: &[FunctionCost], n: usize, total: Option<f64>) {
    for f in functions.iter().take(n) {
        s.push_str(&format!(
            "| `{}` | {:.0} | {:.1} % |\n",
            f.function, f.instr_per_period, f.percent
        ));
    }
    let rest: f64 = functions.iter().skip(n).map(|f| f.percent).sum();
    if let Some(total) = total.filter(|_| functions.len() > n) {
        s.push_str(&format!(
            "| {} other functions | {:.0} | {:.1} % |\n",
            functions.len() - n,
            rest / 100.0 * total,
            rest
        ));
    }
}

/// The result of a window, shared between the link that records it and the flight's report.
pub type ProfileSlot = Arc<Mutex<Option<Result<McuProfile, String>>>>;

/// Switches QEMU's trace on and off around the window and counts it as it comes.
///
/// QEMU writes its log (`-D`) into a named pipe that a thread of this process reads and
/// counts line by line: nothing of the trace is kept on disk (a window of 10 periods is
/// gigabytes of log, most of it the idle loop between frames). A slow reader only slows
/// QEMU's writes, which the lock-step link waits for.
pub struct Profiler {
    window: ProfileWindow,
    monitor: PathBuf,
    fifo: PathBuf,
    /// The image's symbols, or why the window cannot be profiled (no pipe, no symbols, no
    /// work markers): then the trace is never switched on.
    ready: Result<Symbols, String>,
    trace: Arc<Trace>,
    frames_sent: u64,
    slot: ProfileSlot,
}

/// What the reader of the pipe has counted so far.
struct Trace {
    /// Bytes read from the pipe: the trace has stopped when this stops growing.
    bytes: AtomicU64,
    counts: Mutex<Counts>,
}

impl Profiler {
    /// A profiler of `window` for a QEMU running `elf` and started with
    /// [`Profiler::qemu_args`]: creates the pipe in `dir` and starts its reader, which must
    /// be there before QEMU starts (QEMU opens its log at start-up, waiting for a reader).
    pub fn new(window: ProfileWindow, dir: &Path, elf: &Path, slot: ProfileSlot) -> Self {
        let (monitor, fifo) = Self::paths(dir);
        let marked = Symbols::of(elf).and_then(|s| {
            let at = |marker: &str| {
                s.address_of(marker).ok_or_else(|| {
                    format!("the image has no `{marker}`: it does not mark its work")
                })
            };
            let markers = (at(WORK_START)?, at(WORK_END)?);
            Ok((s, markers))
        });
        let (start, end) = marked.as_ref().map_or((u64::MAX, u64::MAX), |(_, m)| *m);
        let trace = Arc::new(Trace {
            bytes: AtomicU64::new(0),
            counts: Mutex::new(Counts::new(start, end)),
        });
        let _ = std::fs::remove_file(&fifo);
        // The reader starts whatever the image: QEMU waits at start-up for one to open the pipe.
        let ready = match nix::unistd::mkfifo(&fifo, Mode::S_IRUSR | Mode::S_IWUSR) {
            Ok(()) => {
                let (fifo, trace) = (fifo.clone(), Arc::clone(&trace));
                std::thread::spawn(move || read_trace(&fifo, &trace));
                marked.map(|(s, _)| s)
            }
            Err(e) => Err(format!("cannot create the pipe `{}`: {e}", fifo.display())),
        };
        Self {
            window,
            monitor,
            fifo,
            ready,
            trace,
            frames_sent: 0,
            slot,
        }
    }

    /// The monitor's socket and the trace's pipe of a profile whose files go to `dir`.
    fn paths(dir: &Path) -> (PathBuf, PathBuf) {
        (dir.join("qemu-monitor.sock"), dir.join("qemu-trace.fifo"))
    }

    /// QEMU's arguments for the monitor socket and the trace of a profile in `dir`.
    pub fn qemu_args(dir: &Path) -> Vec<String> {
        let (monitor, fifo) = Self::paths(dir);
        vec![
            "-monitor".into(),
            format!("unix:{},server,nowait", monitor.display()),
            "-D".into(),
            fifo.display().to_string(),
        ]
    }

    /// Called before each sensor frame is sent: opens or closes the window.
    pub fn before_frame(&mut self) {
        let k = self.frames_sent;
        self.frames_sent += 1;
        if k == self.window.start_frame {
            // Not ready, the trace is not switched on: without its reader QEMU would write
            // gigabytes into a plain file that nobody reads.
            let r = match &self.ready {
                Err(e) => Err(e.clone()),
                Ok(_) => self
                    .open()
                    .map_err(|e| format!("cannot start QEMU's trace: {e}")),
            };
            if let Err(e) = r {
                self.finish(Err(e));
            }
        } else if k == self.window.end_frame() {
            let r = self
                .close()
                .map_err(|e| format!("cannot stop QEMU's trace: {e}"))
                .and_then(|()| self.read());
            self.finish(r);
        }
    }

    fn finish(&mut self, r: Result<McuProfile, String>) {
        *self.slot.lock().unwrap_or_else(|p| p.into_inner()) = Some(r);
    }

    fn monitor(&self, commands: &[&str]) -> io::Result<()> {
        let mut s = UnixStream::connect(&self.monitor)?;
        s.set_read_timeout(Some(Duration::from_secs(5)))?;
        let mut buf = [0u8; 4096];
        let mut seen = Vec::new();
        // Each command is answered with the monitor's prompt once it has been carried out.
        let mut prompts_wanted = 1;
        for c in std::iter::once(&"").chain(commands.iter()) {
            if !c.is_empty() {
                s.write_all(format!("{c}\n").as_bytes())?;
                prompts_wanted += 1;
            }
            while count(&seen, b"(qemu)") < prompts_wanted {
                let n = s.read(&mut buf)?;
                if n == 0 {
                    return Err(io::Error::new(
                        io::ErrorKind::UnexpectedEof,
                        "QEMU's monitor closed",
                    ));
                }
                seen.extend_from_slice(&buf[..n]);
            }
        }
        Ok(())
    }

    fn open(&mut self) -> io::Result<()> {
        // The image has answered the previous frame; let it finish that frame's work.
        self.wait_quiet(Duration::from_millis(100));
        self.monitor(&["singlestep on", "log exec,nochain"])
    }

    fn close(&mut self) -> io::Result<()> {
        // The last frame's answer is in; its work goes on after the answer (telemetry):
        // closed once the trace has stopped growing.
        self.wait_quiet(Duration::from_millis(500));
        self.monitor(&["log none", "singlestep off"])?;
        // What QEMU wrote before the switch is read to its end.
        self.wait_quiet(Duration::from_millis(200));
        Ok(())
    }

    fn read(&self) -> Result<McuProfile, String> {
        let symbols = self.ready.as_ref().map_err(String::clone)?;
        let mut counts = self.trace.counts.lock().unwrap_or_else(|p| p.into_inner());
        let (start, end) = (counts.start, counts.end);
        let counts = std::mem::replace(&mut *counts, Counts::new(start, end));
        Ok(counts.profile(symbols, self.window))
    }

    /// Waits until the trace has not grown for `quiet` (at most a minute).
    fn wait_quiet(&self, quiet: Duration) {
        let size = || self.trace.bytes.load(Ordering::Relaxed);
        let deadline = Instant::now() + Duration::from_secs(60);
        let mut last = size();
        let mut since = Instant::now();
        while Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(20));
            let s = size();
            if s != last {
                (last, since) = (s, Instant::now());
            } else if since.elapsed() >= quiet {
                return;
            }
        }
    }
}

impl Drop for Profiler {
    fn drop(&mut self) {
        // A reader still waiting for QEMU to open the pipe (QEMU never started) is let go:
        // a writer that opens and closes at once ends its read.
        let _ = std::fs::OpenOptions::new()
            .write(true)
            .custom_flags(nix::fcntl::OFlag::O_NONBLOCK.bits())
            .open(&self.fifo);
        let _ = std::fs::remove_file(&self.fifo);
        // QEMU's monitor socket is its to create and nobody's to reuse.
        let _ = std::fs::remove_file(&self.monitor);
    }
}

/// Reads QEMU's trace from the pipe `fifo` until QEMU closes it, counting each line.
fn read_trace(fifo: &Path, trace: &Trace) {
    // Blocks until QEMU opens its end.
    let Ok(f) = std::fs::File::open(fifo) else {
        return;
    };
    let mut r = io::BufReader::with_capacity(1 << 16, f);
    let mut line = Vec::with_capacity(256);
    loop {
        line.clear();
        match r.read_until(b'\n', &mut line) {
            Ok(0) | Err(_) => return,
            Ok(n) => {
                trace.bytes.fetch_add(n as u64, Ordering::Relaxed);
                if let Ok(l) = std::str::from_utf8(&line) {
                    let mut c = trace.counts.lock().unwrap_or_else(|p| p.into_inner());
                    c.line(l.trim_end());
                }
            }
        }
    }
}

fn count(hay: &[u8], needle: &[u8]) -> usize {
    hay.windows(needle.len()).filter(|w| *w == needle).count()
}

/// The image's functions by address.
struct Symbols {
    /// (start, end, name), sorted by start.
    ranges: Vec<(u64, u64, String)>,
    by_name: HashMap<String, u64>,
}

impl Symbols {
    fn of(elf: &Path) -> Result<Self, String> {
        let bytes =
            std::fs::read(elf).map_err(|e| format!("cannot read `{}`: {e}", elf.display()))?;
        let file = object::File::parse(&*bytes)
            .map_err(|e| format!("`{}` is not an ELF file: {e}", elf.display()))?;
        let mut ranges = Vec::new();
        let mut by_name = HashMap::new();
        for s in file.symbols() {
            if s.kind() != SymbolKind::Text || s.size() == 0 {
                continue;
            }
            let Ok(raw) = s.name() else { continue };
            // Thumb code: bit 0 of a function's address says so; the instructions are at the
            // even address.
            let start = s.address() & !1;
            by_name.insert(raw.to_string(), start);
            ranges.push((start, start + s.size(), demangle(raw)));
        }
        ranges.sort_by_key(|r| r.0);
        Ok(Self { ranges, by_name })
    }

    fn address_of(&self, name: &str) -> Option<u64> {
        self.by_name.get(name).copied()
    }

    fn function_at(&self, pc: u64) -> Option<&str> {
        let i = self.ranges.partition_point(|r| r.0 <= pc).checked_sub(1)?;
        let (s, e, name) = &self.ranges[i];
        (pc >= *s && pc < *e).then_some(name.as_str())
    }
}

/// A Rust symbol's path without the hash suffix.
fn demangle(raw: &str) -> String {
    format!("{:#}", rustc_demangle::demangle(raw))
}

/// Executed instructions by address, inside the marked work only.
struct Counts {
    start: u64,
    end: u64,
    /// The addresses executed since the last start marker; committed to `by_pc` at the end
    /// marker. A pass that found nothing to do calls the start marker and never the end one:
    /// what it ran is dropped at the next start.
    pass: Option<Vec<u64>>,
    by_pc: HashMap<u64, u64>,
    passes: u64,
    /// The longest pass so far and its index.
    longest: (u64, Vec<u64>),
}

impl Counts {
    fn new(start: u64, end: u64) -> Self {
        Self {
            start,
            end,
            pass: None,
            by_pc: HashMap::new(),
            passes: 0,
            longest: (0, Vec::new()),
        }
    }

    /// One line of QEMU's log: `Trace 0: 0x... [flags/PC/...] name`, or a note that a block
    /// was executed again after an I/O access (the instruction logged just before is then
    /// logged a second time, and counted once).
    fn line(&mut self, line: &str) {
        if line.starts_with("cpu_io_recompile") {
            if let Some(p) = self.pass.as_mut() {
                p.pop();
            }
            return;
        }
        let Some(pc) = trace_pc(line) else { return };
        if pc == self.start {
            self.pass = Some(Vec::new());
        } else if pc == self.end {
            if let Some(p) = self.pass.take() {
                for a in &p {
                    *self.by_pc.entry(*a).or_insert(0) += 1;
                }
                if p.len() > self.longest.1.len() {
                    self.longest = (self.passes, p);
                }
                self.passes += 1;
            }
        }
        if let Some(p) = self.pass.as_mut() {
            p.push(pc);
        }
    }

    fn profile(self, symbols: &Symbols, window: ProfileWindow) -> McuProfile {
        let periods = f64::from(window.periods.max(1));
        let (functions, total) =
            by_function(self.by_pc.iter().map(|(a, n)| (*a, *n)), symbols, periods);
        let (index, longest) = self.longest;
        let costliest_pass = (!longest.is_empty()).then(|| {
            let mut by_pc: HashMap<u64, u64> = HashMap::new();
            for a in &longest {
                *by_pc.entry(*a).or_insert(0) += 1;
            }
            let (functions, instructions) = by_function(by_pc.into_iter(), symbols, 1.0);
            PassCost {
                index,
                instructions,
                functions,
                memory_callers: memory_callers(&longest, symbols),
            }
        });
        McuProfile {
            start_frame: window.start_frame,
            periods: window.periods,
            instr_per_period: total as f64 / periods,
            functions,
            costliest_pass,
        }
    }
}

/// The instructions of the memory routines in `pass` (executed addresses in order), charged to
/// the last other function that ran before each entry into them; as a share of the pass.
fn memory_callers(pass: &[u64], symbols: &Symbols) -> Vec<FunctionCost> {
    let is_memory = |f: &str| {
        let f = f.trim_start_matches("compiler_builtins::mem::");
        ["memcpy", "memcmp", "memset", "memmove", "__aeabi_mem"]
            .iter()
            .any(|m| f.starts_with(m))
    };
    let mut by_caller: HashMap<String, u64> = HashMap::new();
    let mut caller = "";
    for pc in pass {
        let f = symbols.function_at(*pc).unwrap_or("");
        if is_memory(f) {
            *by_caller.entry(caller.to_string()).or_insert(0) += 1;
        } else {
            caller = f;
        }
    }
    let total = pass.len().max(1) as f64;
    let mut callers: Vec<FunctionCost> = by_caller
        .into_iter()
        .map(|(function, n)| FunctionCost {
            function,
            instr_per_period: n as f64,
            percent: 100.0 * n as f64 / total,
        })
        .collect();
    callers.sort_by(|a, b| b.instr_per_period.total_cmp(&a.instr_per_period));
    callers
}

/// Counts of executed addresses gathered by function, costliest first, each divided by
/// `periods`; and their total.
fn by_function(
    by_pc: impl Iterator<Item = (u64, u64)>,
    symbols: &Symbols,
    periods: f64,
) -> (Vec<FunctionCost>, u64) {
    let mut by_fn: HashMap<String, u64> = HashMap::new();
    let mut total = 0u64;
    for (pc, n) in by_pc {
        let name = symbols
            .function_at(pc)
            .map_or_else(|| format!("0x{pc:08x}"), str::to_string);
        *by_fn.entry(name).or_insert(0) += n;
        total += n;
    }
    let mut functions: Vec<FunctionCost> = by_fn
        .into_iter()
        .map(|(function, n)| FunctionCost {
            function,
            instr_per_period: n as f64 / periods,
            percent: 100.0 * n as f64 / (total.max(1) as f64),
        })
        .collect();
    functions.sort_by(|a, b| {
        b.instr_per_period
            .total_cmp(&a.instr_per_period)
            .then_with(|| a.function.cmp(&b.function))
    });
    (functions, total)
}

/// The guest address of a `Trace` line: the second field of its bracket.
fn trace_pc(line: &str) -> Option<u64> {
    let rest = line.strip_prefix("Trace ")?;
    let inside = rest.split_once('[')?.1.split_once(']')?.0;
    let pc = inside.split('/').nth(1)?;
    u64::from_str_radix(pc, 16).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_window_is_given_in_simulated_seconds_and_whole_periods() {
        let w = ProfileWindow::parse("40").expect("window");
        assert_eq!((w.start_frame, w.periods, w.end_frame()), (4000, 10, 4020));
        let w = ProfileWindow::parse("1.5:3").expect("window");
        assert_eq!((w.start_frame, w.end_frame()), (150, 156));
        for bad in ["", "x", "-1", "5:0", "5:x", "inf"] {
            assert!(ProfileWindow::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn without_its_pipe_the_window_reports_why_and_never_switches_the_trace_on() {
        let slot = ProfileSlot::default();
        let dir = std::path::Path::new("/nonexistent/profile-dir");
        let window = ProfileWindow::parse("0:1").expect("window");
        let mut p = Profiler::new(window, dir, Path::new("/nonexistent/elf"), slot.clone());
        // The window's first frame: no monitor is asked (there is no QEMU here), the slot
        // says why.
        p.before_frame();
        let r = slot.lock().expect("slot").clone().expect("a result");
        let e = r.expect_err("no profile without a pipe");
        assert!(e.contains("cannot create the pipe"), "{e}");
    }

    #[test]
    fn only_instructions_between_the_work_markers_count_and_a_rewound_one_counts_once() {
        let t = |pc: u32| format!("Trace 0: 0x7f00 [00800400/{pc:08x}/00000010/ff020201] f");
        let mut c = Counts::new(0x100, 0x200);
        // Idle polling before the work, not counted, nor a pass that found nothing to do.
        c.line(&t(0x50));
        c.line(&t(0x52));
        c.line(&t(0x100));
        c.line(&t(0x54));
        // The work: the start marker's entry, three instructions (one executed again after an
        // I/O access), then the end marker's entry.
        c.line(&t(0x100));
        c.line(&t(0x300));
        c.line(&t(0x302));
        c.line("cpu_io_recompile: rewound execution of TB to 00000302");
        c.line(&t(0x302));
        c.line(&t(0x200));
        c.line(&t(0x50));
        c.line(&t(0x100));
        c.line(&t(0x52));
        let total: u64 = c.by_pc.values().sum();
        assert_eq!((total, c.passes), (3, 1));
        assert_eq!(c.longest, (0, vec![0x100, 0x300, 0x302]));
        assert_eq!(trace_pc(&t(0x0800_ebd8)), Some(0x0800_ebd8));
        assert_eq!(trace_pc("cpu_io_recompile: x"), None);
    }
}
