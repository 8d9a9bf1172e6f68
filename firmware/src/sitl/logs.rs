//! The flight logs of the SITL board: one ULog file per armed flight in a folder beside the
//! storage file (`log_001.ulg`, `log_002.ulg`, ...), drained from the application after each
//! read of the simulator link.

use crate::app::App;
use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The log folder and the file being written.
pub struct LogFiles {
    dir: PathBuf,
    file: Option<(PathBuf, File)>,
    seen: u32,
}

impl LogFiles {
    /// Logs in `dir` (created when the first log starts); enables the application's log.
    pub fn new(dir: impl Into<PathBuf>, app: &mut App) -> Self {
        app.flight_log_mut().enable(true);
        Self {
            dir: dir.into(),
            file: None,
            seen: app.flight_log().logs_started(),
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
