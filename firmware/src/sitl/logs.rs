//! The flight logs of the SITL board: one ULog file per armed flight in a folder beside the
//! storage file (`log_001.ulg`, `log_002.ulg`, ...), drained from the application after each
//! read of the simulator link; and the same folder served to the ground stations' log
//! protocol ([`LogStore`]: `log_001.ulg` is the oldest, the first listed).

use crate::app::App;
use common::gcs::logs::{LogEntryInfo, LogStore};
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// The log folder and the file being written.
pub struct LogFiles {
    dir: PathBuf,
    file: Option<(PathBuf, File)>,
    seen: u32,
    /// The logs as last listed: path, size, start time.
    listed: Vec<(PathBuf, LogEntryInfo)>,
    /// The log open for a download, by its place in `listed`.
    reading: Option<(u16, File)>,
}

impl LogFiles {
    /// Logs in `dir` (created when the first log starts); enables the application's log.
    pub fn new(dir: impl Into<PathBuf>, app: &mut App) -> Self {
        app.flight_log_mut().enable(true);
        Self {
            dir: dir.into(),
            file: None,
            seen: app.flight_log().logs_started(),
            listed: Vec::new(),
            reading: None,
        }
    }

    /// The folder beside a storage file: `logs/` in the storage file's folder.
    pub fn beside(storage: &Path) -> PathBuf {
        storage
            .parent()
            .map_or_else(|| PathBuf::from("logs"), |p| p.join("logs"))
    }

    /// Writes what the application's log has for its storage; opens a file when a log
    /// starts and closes it once a stopped log is drained.
    pub fn service(&mut self, app: &mut App) -> io::Result<()> {
        let log = app.flight_log_mut();
        let started = log.logs_started();
        while log.pending_len() > 0 {
            if self.file.is_none() && started != self.seen {
                self.seen = started;
                self.file = Some(self.open_next()?);
            }
            let n = log.pending().len();
            if let Some((_, f)) = self.file.as_mut() {
                f.write_all(log.pending())?;
            }
            log.consume(n);
        }
        if !log.recording() {
            if let Some((_, mut f)) = self.file.take() {
                f.flush()?;
            }
        }
        Ok(())
    }

    fn open_next(&self) -> io::Result<(PathBuf, File)> {
        std::fs::create_dir_all(&self.dir)?;
        for k in 1..10_000u32 {
            let path = self.dir.join(format!("log_{k:03}.ulg"));
            match File::options().write(true).create_new(true).open(&path) {
                Ok(f) => return Ok((path, f)),
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
        Err(io::Error::other("no free log file name"))
    }
}

/// Whether `name` is one of the logs this board writes (`log_NNN.ulg`).
fn is_log_name(name: &str) -> bool {
    name.strip_prefix("log_")
        .and_then(|n| n.strip_suffix(".ulg"))
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
}

impl LogStore for LogFiles {
    fn refresh(&mut self) {
        self.reading = None;
        let Ok(dir) = std::fs::read_dir(&self.dir) else {
            self.listed.clear();
            return;
        };
        let mut found: Vec<(u64, PathBuf, LogEntryInfo)> = dir
            .filter_map(Result::ok)
            .filter_map(|e| {
                let name = e.file_name().into_string().ok()?;
                if !is_log_name(&name) {
                    return None;
                }
                let number = name.get(4..name.len() - 4)?.parse().ok()?;
                let meta = e.metadata().ok()?;
                let time_utc_s = meta
                    .modified()
                    .ok()
                    .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                    .map_or(0, |d| u32::try_from(d.as_secs()).unwrap_or(0));
                let info = LogEntryInfo {
                    size_bytes: u32::try_from(meta.len()).unwrap_or(u32::MAX),
                    time_utc_s,
                };
                Some((number, e.path(), info))
            })
            .collect();
        found.sort_by_key(|(n, _, _)| *n);
        self.listed = found
            .into_iter()
            .take(usize::from(u16::MAX))
            .map(|(_, p, i)| (p, i))
            .collect();
    }

    fn count(&self) -> u16 {
        u16::try_from(self.listed.len()).unwrap_or(u16::MAX)
    }

    fn entry(&self, index: u16) -> Option<LogEntryInfo> {
        self.listed.get(usize::from(index)).map(|(_, i)| *i)
    }

    fn read(&mut self, index: u16, offset: u32, buf: &mut [u8]) -> Option<usize> {
        if self.reading.as_ref().is_none_or(|(i, _)| *i != index) {
            let (path, _) = self.listed.get(usize::from(index))?;
            self.reading = Some((index, File::open(path).ok()?));
        }
        let (_, f) = self.reading.as_mut()?;
        f.seek(SeekFrom::Start(u64::from(offset))).ok()?;
        let mut n = 0;
        while n < buf.len() {
            match f.read(buf.get_mut(n..)?) {
                Ok(0) => break,
                Ok(k) => n += k,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(_) => return None,
            }
        }
        Some(n)
    }

    fn erase_all(&mut self) -> bool {
        self.reading = None;
        let writing = self.file.as_ref().map(|(p, _)| p.clone());
        let Ok(dir) = std::fs::read_dir(&self.dir) else {
            // No folder: no log to erase.
            return true;
        };
        let mut ok = true;
        for e in dir.filter_map(Result::ok) {
            let path = e.path();
            let ours = e.file_name().to_str().is_some_and(is_log_name);
            if ours && Some(&path) != writing.as_ref() {
                ok &= std::fs::remove_file(&path).is_ok();
            }
        }
        ok
    }
}
