//! The reader's state: a cursor over the file's bytes and the parser that walks its
//! messages, resynchronising on corrupt bytes.

use super::format::{self, Format, Layout};
use super::types::*;
use common::ulog::{HEADER_LEN, MAGIC, MSG_HEADER_LEN, SYNC_MAGIC};
use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

/// Reads a log from its bytes.
pub fn parse(bytes: &[u8]) -> Result<Ulog, ParseError> {
    let at = |offset: usize, what: String| ParseError { offset, what };
    if bytes.is_empty() {
        return Err(at(
            0,
            format!("the file is empty; a ULog file starts with a {HEADER_LEN}-byte header"),
        ));
    }
    let magic = bytes.get(..MAGIC.len()).unwrap_or(bytes);
    if MAGIC.get(..magic.len()) != Some(magic) {
        return Err(at(
            0,
            format!(
                "not a ULog file: it starts with {}, a ULog file with {} (\"ULog\" 01 12 35)",
                hex(magic),
                hex(&MAGIC)
            ),
        ));
    }
    let header = bytes.get(..HEADER_LEN).ok_or_else(|| {
        at(
            bytes.len(),
            format!(
                "the header is {HEADER_LEN} bytes, the file ends after {}",
                bytes.len()
            ),
        )
    })?;
    let mut r = Reader::new(header);
    r.skip(MAGIC.len());
    let version = r.u8().unwrap_or_default();
    let start_us = r.u64().unwrap_or_default();
    let mut p = Parser {
        bytes,
        log: Ulog {
            version,
            start_us,
            bytes_read: HEADER_LEN,
            file_len: bytes.len(),
            ..Ulog::default()
        },
        subscriptions: HashMap::new(),
        layouts: HashMap::new(),
        budget: format::LOG_ELEMENTS_MAX,
        instances: HashMap::new(),
        in_data: false,
        last_us: start_us,
        alike: BTreeMap::new(),
    };
    if version > common::ulog::VERSION {
        p.warn(
            MAGIC.len(),
            format!(
                "format version {version}; this reader knows version {} (read as that)",
                common::ulog::VERSION
            ),
        );
    }
    p.run()?;
    Ok(p.finish())
}

fn hex(b: &[u8]) -> String {
    b.iter()
        .map(|x| format!("{x:02X}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A little-endian reader over one message's payload.
struct Reader<'a> {
    b: &'a [u8],
}

impl<'a> Reader<'a> {
    fn new(b: &'a [u8]) -> Self {
        Self { b }
    }

    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let (head, rest) = (self.b.get(..n)?, self.b.get(n..)?);
        self.b = rest;
        Some(head)
    }

    fn skip(&mut self, n: usize) {
        self.b = self.b.get(n..).unwrap_or(&[]);
    }

    fn array<const N: usize>(&mut self) -> Option<[u8; N]> {
        self.take(N)?.try_into().ok()
    }

    fn u8(&mut self) -> Option<u8> {
        Some(self.array::<1>()?[0])
    }

    fn u16(&mut self) -> Option<u16> {
        Some(u16::from_le_bytes(self.array()?))
    }

    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.array()?))
    }

    fn rest(&mut self) -> &'a [u8] {
        std::mem::take(&mut self.b)
    }
}

/// What every message type of the specification is, by its type byte.
fn known_type(t: u8) -> bool {
    matches!(
        t,
        b'B' | b'F' | b'I' | b'M' | b'P' | b'Q' | b'A' | b'R' | b'D' | b'L' | b'C' | b'S' | b'O'
    )
}

/// A type byte for the message log: the letter, or its value.
fn type_name(t: u8) -> String {
    if t.is_ascii_graphic() {
        format!("'{}'", char::from(t))
    } else {
        format!("0x{t:02X}")
    }
}

/// What the bytes at an offset are.
enum Step<'a> {
    /// A whole message: its type, payload, and where the next starts.
    Message(u8, &'a [u8], usize),
    /// A type byte no message has.
    NotAMessage(u8),
    /// Fewer bytes left than a message header (how many).
    HeaderCut(usize),
    /// A message longer than the bytes left: its type, its size, the bytes left.
    BodyCut(u8, u16, usize),
}

struct Parser<'a> {
    bytes: &'a [u8],
    log: Ulog,
    /// Subscribed message ids and the dataset each fills.
    subscriptions: HashMap<u16, usize>,
    /// A subscription, data or text has been seen: `P` now means a change.
    in_data: bool,
    /// The last timestamp seen.
    last_us: u64,
    /// Warnings by kind: the first's offset and text, and how many more.
    alike: BTreeMap<String, (usize, String, usize)>,
    /// Layouts by format name, each worked out once (a file may subscribe to a deep format
    /// many times; formats are all defined before the first subscription).
    layouts: HashMap<String, Result<Arc<Layout>, String>>,
    /// Elements the log's layouts may still expand to.
    budget: usize,
    /// The dataset of each topic instance, by name and `multi_id`.
    instances: HashMap<(String, u8), usize>,
}

impl<'a> Parser<'a> {
    fn warn(&mut self, offset: usize, what: String) {
        self.log.warnings.push(Warning {
            offset,
            what,
            more: 0,
        });
    }

    /// A warning that may repeat for every message of a kind: given once, with a count.
    fn warn_alike(&mut self, kind: String, offset: usize, what: impl FnOnce() -> String) {
        self.alike
            .entry(kind)
            .and_modify(|(_, _, more)| *more = more.saturating_add(1))
            .or_insert_with(|| (offset, what(), 0));
    }

    fn finish(mut self) -> Ulog {
        let alike = std::mem::take(&mut self.alike);
        self.log
            .warnings
            .extend(
                alike
                    .into_values()
                    .map(|(offset, what, more)| Warning { offset, what, more }),
            );
        self.log.warnings.sort_by_key(|w| w.offset);
        self.log
    }

    /// Reads every message: up to the first appended offset, then each appended part.
    fn run(&mut self) -> Result<(), ParseError> {
        let len = self.bytes.len();
        let mut pos = HEADER_LEN;
        // The flag bits, when the log has them, come first and say where its parts are.
        if let Step::Message(b'B', payload, next) = self.step(pos, len) {
            self.message(pos, b'B', payload)?;
            pos = next;
            self.log.bytes_read = next;
        }
        let mut bounds: Vec<usize> = Vec::new();
        if self.log.flags.incompat[0] & DATA_APPENDED != 0 {
            for o in self.log.flags.appended_offsets {
                match usize::try_from(o) {
                    _ if o == 0 => {}
                    Ok(o) if o >= pos && o <= len && bounds.last().is_none_or(|&b| o > b) => {
                        bounds.push(o)
                    }
                    _ => self.warn(
                        HEADER_LEN,
                        format!(
                            "appended data at byte {o}, outside the file ({len} bytes) or out of order: ignored"
                        ),
                    ),
                }
            }
        }
        bounds.push(len);
        let last = bounds.len().saturating_sub(1);
        for (i, &end) in bounds.iter().enumerate() {
            // A part before appended data may end in the middle of a message (that is why
            // data are appended): only the last part's end says the file was cut.
            self.part(pos, end, i == last)?;
            pos = end;
        }
        Ok(())
    }

    /// What is at `pos`, reading no further than `end`.
    fn step(&self, pos: usize, end: usize) -> Step<'a> {
        let left = end.saturating_sub(pos);
        let bytes: &'a [u8] = self.bytes;
        let head = match bytes.get(pos..end).and_then(|b| b.get(..MSG_HEADER_LEN)) {
            Some(h) => h,
            None => return Step::HeaderCut(left),
        };
        let mut h = Reader::new(head);
        let (size, kind) = (h.u16().unwrap_or_default(), h.u8().unwrap_or_default());
        if !known_type(kind) {
            return Step::NotAMessage(kind);
        }
        let start = pos.saturating_add(MSG_HEADER_LEN);
        let next = start.saturating_add(usize::from(size));
        match bytes.get(start..next).filter(|_| next <= end) {
            Some(payload) => Step::Message(kind, payload, next),
            None => Step::BodyCut(kind, size, left.saturating_sub(MSG_HEADER_LEN)),
        }
    }

    /// Reads the messages from `pos` to `end`; `last` is the file's last part, whose cut
    /// end is worth a warning.
    fn part(&mut self, mut pos: usize, end: usize, last: bool) -> Result<(), ParseError> {
        while pos < end {
            match self.step(pos, end) {
                Step::Message(kind, payload, next) => match self.misfit(kind, payload) {
                    // A sample that its own topic's format cannot hold: the size in its
                    // header is what is corrupt, and the next message is not where it says.
                    Some(why) => match self.resync(pos, end, why) {
                        Some(after) => pos = after,
                        None => return Ok(()),
                    },
                    None => {
                        self.message(pos, kind, payload)?;
                        pos = next;
                        self.log.bytes_read = self.log.bytes_read.max(pos);
                    }
                },
                Step::NotAMessage(kind) => {
                    let why = format!("no message starts here (type byte {})", type_name(kind));
                    match self.resync(pos, end, why) {
                        Some(after) => pos = after,
                        None => return Ok(()),
                    }
                }
                Step::HeaderCut(left) => {
                    if last {
                        self.warn(
                            pos,
                            format!(
                                "the file ends inside a message's header ({left} of its {MSG_HEADER_LEN} bytes): read up to byte {pos}"
                            ),
                        );
                    }
                    return Ok(());
                }
                // A size that runs past the end over a sync marker is a corrupt size, not a cut
                // file: a sync marker inside the body of a message cut short by a power loss
                // would be an eight-byte coincidence.
                Step::BodyCut(kind, size, left)
                    if self.find_sync(pos.saturating_add(1), end).is_some() =>
                {
                    let why = format!(
                        "message of type {} claims {size} bytes, only {left} left",
                        type_name(kind)
                    );
                    match self.resync(pos, end, why) {
                        Some(after) => pos = after,
                        None => return Ok(()),
                    }
                }
                Step::BodyCut(kind, size, left) => {
                    if last {
                        self.warn(
                            pos,
                            format!(
                                "message of type {} claims {size} bytes, only {left} left: the file ends mid-message (as a log cut by a power loss does); read up to byte {pos}",
                                type_name(kind)
                            ),
                        );
                    }
                    return Ok(());
                }
            }
        }
        Ok(())
    }

    /// Skips from corrupt bytes at `pos` to the message after the next sync marker: where to
    /// read on, or `None` when no marker follows (reading stops).
    fn resync(&mut self, pos: usize, end: usize, why: String) -> Option<usize> {
        match self.find_sync(pos.saturating_add(1), end) {
            Some(sync) => {
                self.warn(
                    pos,
                    format!(
                        "{why}: the file is corrupt; skipped {} bytes to the next sync marker",
                        sync.saturating_sub(pos)
                    ),
                );
                self.log.syncs = self.log.syncs.saturating_add(1);
                Some(sync.saturating_add(SYNC_MAGIC.len()))
            }
            None => {
                self.warn(
                    pos,
                    format!(
                        "{why}, and no sync marker follows: the file is corrupt from here; read up to byte {pos}"
                    ),
                );
                None
            }
        }
    }

    /// Why a data message cannot be what its header says: a sample longer or shorter than
    /// its subscription's format.
    fn misfit(&self, kind: u8, payload: &[u8]) -> Option<String> {
        if kind != b'D' {
            return None;
        }
        let mut r = Reader::new(payload);
        let d = self
            .subscriptions
            .get(&r.u16()?)
            .and_then(|&i| self.log.datasets.get(i))?;
        let got = r.rest().len();
        (got < d.layout.min_size || got > d.layout.size).then(|| {
            format!(
                "a sample of `{}` is {got} bytes, its format {}",
                d.name, d.layout.size
            )
        })
    }

    /// The offset of the sync magic next at or after `from` (before `end`), if any.
    fn find_sync(&self, from: usize, end: usize) -> Option<usize> {
        let hay = self.bytes.get(from..end)?;
        hay.windows(SYNC_MAGIC.len())
            .position(|w| w == SYNC_MAGIC)
            .map(|i| from.saturating_add(i))
    }

    fn message(&mut self, pos: usize, kind: u8, payload: &[u8]) -> Result<(), ParseError> {
        let mut r = Reader::new(payload);
        match kind {
            b'B' => self.flag_bits(pos, &mut r)?,
            // Formats belong to the definitions: one after a subscription could change the
            // layout of samples already read.
            b'F' if self.in_data => self.warn_alike("late format".into(), pos, || {
                "format message after the definitions (the specification puts formats before the data): ignored".into()
            }),
            b'F' => match std::str::from_utf8(payload) {
                Ok(text) => match Format::parse(text) {
                    Ok(f) => {
                        self.log.formats.insert(f.name.clone(), f);
                    }
                    Err(e) => self.warn(pos, format!("format message `{text}`: {e}: skipped")),
                },
                Err(_) => self.warn(pos, "format message is not text: skipped".into()),
            },
            b'I' => {
                if let Some((name, value)) = self.keyed(pos, "information", &mut r) {
                    self.log.info.insert(name, value);
                }
            }
            b'M' => {
                let continued = r.u8().unwrap_or_default() != 0;
                if let Some((name, value)) = self.keyed(pos, "information", &mut r) {
                    let values = self.log.info_multi.entry(name).or_default();
                    match (continued, values.last_mut(), value) {
                        (true, Some(Value::Text(a)), Value::Text(b)) => a.push_str(&b),
                        (true, Some(Value::Bytes(a)), Value::Bytes(b)) => a.extend(b),
                        (_, _, value) => values.push(value),
                    }
                }
            }
            b'P' => {
                if let Some((name, value)) = self.keyed(pos, "parameter", &mut r) {
                    if self.in_data {
                        self.log.param_changes.push(ParamChange {
                            timestamp_us: self.last_us,
                            name,
                            value,
                        });
                    } else {
                        self.log.params.insert(name, value);
                    }
                }
            }
            b'Q' => {
                let default_types = r.u8().unwrap_or_default();
                if let Some((name, value)) = self.keyed(pos, "parameter default", &mut r) {
                    self.log.param_defaults.push(ParamDefault {
                        default_types,
                        name,
                        value,
                    });
                }
            }
            b'A' => self.add_logged(pos, &mut r),
            b'R' => {
                self.in_data = true;
                if let Some(id) = r.u16() {
                    self.subscriptions.remove(&id);
                }
            }
            b'D' => self.data(pos, &mut r),
            b'L' | b'C' => {
                self.in_data = true;
                let level = r.u8();
                let tag = if kind == b'C' { r.u16() } else { None };
                match (level, r.u64()) {
                    (Some(level), Some(timestamp_us)) if kind == b'L' || tag.is_some() => {
                        self.last_us = timestamp_us;
                        self.log.texts.push(Text {
                            // Written as the ASCII digit; a raw number read alike.
                            level: if level >= b'0' {
                                level.saturating_sub(b'0').min(7)
                            } else {
                                level.min(7)
                            },
                            tag,
                            timestamp_us,
                            text: String::from_utf8_lossy(r.rest()).into_owned(),
                        });
                    }
                    _ => self.warn_alike("short text".into(), pos, || {
                        "text message too short for its level and timestamp: skipped".into()
                    }),
                }
            }
            b'S' => {
                self.in_data = true;
                if r.rest().get(..SYNC_MAGIC.len()) == Some(&SYNC_MAGIC[..]) {
                    self.log.syncs = self.log.syncs.saturating_add(1);
                } else {
                    self.warn_alike("bad sync".into(), pos, || {
                        "sync message without the sync magic".into()
                    });
                }
            }
            b'O' => {
                self.in_data = true;
                match r.u16() {
                    Some(duration_ms) => self.log.dropouts.push(Dropout {
                        timestamp_us: self.last_us,
                        duration_ms,
                    }),
                    None => self.warn_alike("short dropout".into(), pos, || {
                        "dropout message without its duration: skipped".into()
                    }),
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn flag_bits(&mut self, pos: usize, r: &mut Reader<'_>) -> Result<(), ParseError> {
        if pos != HEADER_LEN {
            self.warn(
                pos,
                "flag bits after the first message (the specification puts them first): ignored"
                    .into(),
            );
            return Ok(());
        }
        let (Some(compat), Some(incompat)) = (r.array::<8>(), r.array::<8>()) else {
            self.warn(
                pos,
                "flag bits shorter than their 16 flag bytes: ignored".into(),
            );
            return Ok(());
        };
        let mut appended_offsets = [0u64; 3];
        for o in &mut appended_offsets {
            *o = r.u64().unwrap_or_default();
        }
        // Unknown incompatible flags mean the file cannot be read as this reader reads it:
        // the specification says to stop.
        let unknown: Vec<String> = incompat
            .iter()
            .enumerate()
            .map(|(i, &b)| (i, if i == 0 { b & !DATA_APPENDED } else { b }))
            .filter(|(_, b)| *b != 0)
            .map(|(i, b)| format!("byte {i}: 0x{b:02X}"))
            .collect();
        if !unknown.is_empty() {
            return Err(ParseError {
                offset: pos,
                what: format!(
                    "the log sets incompatible flags this reader does not know ({}): the specification forbids reading on",
                    unknown.join(", ")
                ),
            });
        }
        self.log.flags = FlagBits {
            compat,
            incompat,
            appended_offsets,
        };
        Ok(())
    }

    /// A key (`type name`) and its value, as information and parameter messages carry them.
    fn keyed(&mut self, pos: usize, what: &str, r: &mut Reader<'_>) -> Option<(String, Value)> {
        let parsed = (|| {
            let n = r.u8().ok_or("no key length")?;
            let key = r
                .take(usize::from(n))
                .ok_or("key longer than the message")?;
            let key = std::str::from_utf8(key).map_err(|_| "key is not text")?;
            let (ty, name) = key.split_once(' ').ok_or("key is not `type name`")?;
            let (ty, count) = format::parse_type(ty).map_err(|_| "key's type does not parse")?;
            let value = Value::decode(&ty, count, r.rest()).ok_or("value shorter than its type")?;
            Ok::<_, &str>((name.to_string(), value))
        })();
        match parsed {
            Ok(kv) => Some(kv),
            Err(why) => {
                self.warn(pos, format!("{what} message: {why}: skipped"));
                None
            }
        }
    }

    fn add_logged(&mut self, pos: usize, r: &mut Reader<'_>) {
        self.in_data = true;
        let (Some(multi_id), Some(msg_id)) = (r.u8(), r.u16()) else {
            self.warn(pos, "subscription message too short: skipped".into());
            return;
        };
        let name = String::from_utf8_lossy(r.rest()).into_owned();
        let (formats, budget) = (&self.log.formats, &mut self.budget);
        let layout = match self
            .layouts
            .entry(name.clone())
            .or_insert_with(|| Layout::of(formats, &name, budget).map(Arc::new))
        {
            Ok(l) => l.clone(),
            Err(e) => {
                let e = e.clone();
                self.warn(
                    pos,
                    format!(
                        "subscription of `{name}` (message id {msg_id}): {e}: its data are skipped"
                    ),
                );
                self.subscriptions.remove(&msg_id);
                return;
            }
        };
        // A topic subscribed again (after an `R`) goes on filling the same samples (its layout
        // is the one worked out for its format).
        let key = (name, multi_id);
        let index = match self.instances.get(&key) {
            Some(&i)
                if self
                    .log
                    .datasets
                    .get(i)
                    .is_some_and(|d| Arc::ptr_eq(&d.layout, &layout)) =>
            {
                i
            }
            _ => {
                self.log.datasets.push(Dataset {
                    name: key.0.clone(),
                    multi_id,
                    layout,
                    timestamps_us: Vec::new(),
                    raw: Vec::new(),
                });
                let i = self.log.datasets.len().saturating_sub(1);
                self.instances.insert(key, i);
                i
            }
        };
        self.subscriptions.insert(msg_id, index);
    }

    fn data(&mut self, pos: usize, r: &mut Reader<'_>) {
        self.in_data = true;
        let Some(msg_id) = r.u16() else {
            self.warn_alike("short data".into(), pos, || {
                "data message without its message id: skipped".into()
            });
            return;
        };
        let Some(d) = self
            .subscriptions
            .get(&msg_id)
            .and_then(|&i| self.log.datasets.get_mut(i))
        else {
            self.warn_alike(format!("unsubscribed {msg_id}"), pos, || {
                format!("data for message id {msg_id}, which no subscription names: skipped")
            });
            return;
        };
        // Its size fits its format (`misfit` saw to it).
        let sample = r.rest();
        let size = d.layout.size;
        let ts = d
            .layout
            .timestamp
            .as_ref()
            .and_then(|t| format::unsigned(t.ty, sample.get(t.offset..)?))
            .unwrap_or_default();
        d.timestamps_us.push(ts);
        d.raw.extend_from_slice(sample);
        // Trailing padding left out: the sample is filled to its whole size.
        d.raw.resize(
            d.raw
                .len()
                .saturating_add(size.saturating_sub(sample.len())),
            0,
        );
        self.last_us = ts;
    }
}
