//! The one-pass index: `#id → (type, byte range)` for every entity instance.

use super::error::{StepError, StepErrorKind};
use super::header::Header;
use super::limits::ReadOptions;
use super::params::{self, Entity, skip_ws};
use super::source::Source;
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use std::path::Path;

/// Index of an interned entity type name.
pub type TypeId = u32;

/// Where one entity instance sits in the file.
#[derive(Debug, Clone, Copy)]
pub struct Record {
    pub id: u64,
    pub type_id: TypeId,
    /// Byte offset of the `#` that starts the instance.
    pub start: usize,
    /// Byte range of the parameter list, parentheses included.
    pub params: (usize, usize),
}

/// Ids are looked up in a dense table when they are compact (the usual case),
/// otherwise by binary search; either way memory is bounded by the entity count.
enum IdLookup {
    Dense(Vec<u32>),
    Sorted(Vec<(u64, u32)>),
}

pub struct StepFile {
    source: Source,
    pub header: Header,
    records: Vec<Record>,
    lookup: IdLookup,
    type_names: Vec<String>,
    by_type: Vec<Vec<u32>>,
    max_depth: usize,
    /// How many parallel chunks the DATA scan used (1: one pass).
    scan_chunks: usize,
}

const NO_RECORD: u32 = u32::MAX;

impl std::fmt::Debug for StepFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StepFile")
            .field("header", &self.header)
            .field("entities", &self.records.len())
            .finish()
    }
}

impl StepFile {
    pub fn open(path: &Path, options: &ReadOptions) -> Result<StepFile, StepError> {
        Self::from_source(Source::open(path, options)?, options)
    }

    pub fn from_bytes(bytes: Vec<u8>, options: &ReadOptions) -> Result<StepFile, StepError> {
        if bytes.len() as u64 > options.max_bytes {
            let kind = StepErrorKind::TooLarge {
                bytes: bytes.len() as u64,
                limit: options.max_bytes,
            };
            return Err(StepError::new(kind));
        }
        Self::from_source(Source::Owned(bytes), options)
    }

    fn from_source(source: Source, options: &ReadOptions) -> Result<StepFile, StepError> {
        let scan = Scanner::new(source.bytes(), options).scan();
        let (header, raw) = match scan {
            Ok(v) => v,
            Err((offset, kind, entity)) => {
                return Err(located(source.bytes(), offset, kind, entity));
            }
        };
        let mut file = StepFile {
            header,
            records: raw.records,
            lookup: IdLookup::Sorted(Vec::new()),
            type_names: raw.type_names,
            by_type: Vec::new(),
            max_depth: options.max_depth,
            scan_chunks: raw.chunks,
            source,
        };
        file.build_lookup()?;
        file.by_type = vec![Vec::new(); file.type_names.len()];
        for (i, r) in file.records.iter().enumerate() {
            file.by_type[r.type_id as usize].push(i as u32);
        }
        Ok(file)
    }

    fn build_lookup(&mut self) -> Result<(), StepError> {
        let count = self.records.len();
        let max_id = self.records.iter().map(|r| r.id).max().unwrap_or(0);
        let duplicate = |first: &Record, second: &Record| {
            let kind = StepErrorKind::DuplicateId {
                id: second.id,
                first_line: self.line_col(first.start).0,
                first_type: self.type_names[first.type_id as usize].clone(),
                second_type: self.type_names[second.type_id as usize].clone(),
            };
            let mut e = located(self.bytes(), second.start, kind, Some(second.id));
            e.entity = None;
            e
        };
        if max_id <= (count as u64) * 4 + 1024 {
            let mut table = vec![NO_RECORD; max_id as usize + 1];
            for (i, r) in self.records.iter().enumerate() {
                let slot = &mut table[r.id as usize];
                if *slot != NO_RECORD {
                    return Err(duplicate(&self.records[*slot as usize], r));
                }
                *slot = i as u32;
            }
            self.lookup = IdLookup::Dense(table);
        } else {
            let mut sorted: Vec<(u64, u32)> = self
                .records
                .iter()
                .enumerate()
                .map(|(i, r)| (r.id, i as u32))
                .collect();
            sorted.sort_unstable();
            if let Some(w) = sorted.windows(2).find(|w| w[0].0 == w[1].0) {
                let (a, b) = (
                    &self.records[w[0].1 as usize],
                    &self.records[w[1].1 as usize],
                );
                let (first, second) = if a.start < b.start { (a, b) } else { (b, a) };
                return Err(duplicate(first, second));
            }
            self.lookup = IdLookup::Sorted(sorted);
        }
        Ok(())
    }

    pub fn bytes(&self) -> &[u8] {
        self.source.bytes()
    }

    pub fn len(&self) -> usize {
        self.records.len()
    }

    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// How many parallel chunks indexed the DATA section (1: one pass).
    pub fn scan_chunks(&self) -> usize {
        self.scan_chunks
    }

    pub fn records(&self) -> &[Record] {
        &self.records
    }

    pub fn record(&self, id: u64) -> Option<&Record> {
        let index = match &self.lookup {
            IdLookup::Dense(table) => *table.get(usize::try_from(id).ok()?)?,
            IdLookup::Sorted(sorted) => sorted
                .binary_search_by_key(&id, |e| e.0)
                .ok()
                .map(|i| sorted[i].1)?,
        };
        (index != NO_RECORD).then(|| &self.records[index as usize])
    }

    pub fn type_name(&self, type_id: TypeId) -> &str {
        &self.type_names[type_id as usize]
    }

    pub fn type_id(&self, upper_name: &str) -> Option<TypeId> {
        self.type_names
            .iter()
            .position(|n| n == upper_name)
            .map(|i| i as TypeId)
    }

    /// Records of one type (upper-case name), in file order.
    pub fn of_type(&self, upper_name: &str) -> impl Iterator<Item = &Record> + '_ {
        let ids: &[u32] = self
            .type_id(upper_name)
            .map(|t| self.by_type[t as usize].as_slice())
            .unwrap_or(&[]);
        ids.iter().map(move |&i| &self.records[i as usize])
    }

    /// Decodes the parameters of one record.
    pub fn decode(&self, record: &Record) -> Result<Entity<'_>, StepError> {
        let (start, end) = record.params;
        let text = &self.bytes()[start..end];
        match params::decode_list(text, self.max_depth) {
            Ok(params) => Ok(Entity {
                id: record.id,
                type_name: self.type_name(record.type_id),
                params,
            }),
            Err((at, kind)) => Err(located(self.bytes(), start + at, kind, Some(record.id))),
        }
    }

    /// Decodes the entity `#id`; `None` when no such id is defined.
    pub fn entity(&self, id: u64) -> Option<Result<Entity<'_>, StepError>> {
        self.record(id).map(|r| self.decode(r))
    }

    /// 1-based line and column of a byte offset (CR, LF and CRLF line ends).
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        line_col(self.bytes(), offset)
    }
}

fn line_col(bytes: &[u8], offset: usize) -> (usize, usize) {
    let head = &bytes[..offset.min(bytes.len())];
    let lf = memchr::memchr_iter(b'\n', head).count();
    let lone_cr = memchr::memchr_iter(b'\r', head)
        .filter(|&i| head.get(i + 1) != Some(&b'\n'))
        .count();
    let line_start = memchr::memrchr2(b'\n', b'\r', head).map_or(0, |i| i + 1);
    (lf + lone_cr + 1, offset.saturating_sub(line_start) + 1)
}

fn located(bytes: &[u8], offset: usize, kind: StepErrorKind, entity: Option<u64>) -> StepError {
    let (line, column) = line_col(bytes, offset);
    StepError {
        kind,
        line,
        column,
        entity,
    }
}

struct RawIndex {
    records: Vec<Record>,
    type_names: Vec<String>,
    chunks: usize,
}

type ScanError = (usize, StepErrorKind, Option<u64>);

/// Walks the file once: header, then every DATA section.
struct Scanner<'a> {
    bytes: &'a [u8],
    pos: usize,
    max_depth: usize,
    max_instances: usize,
    max_string_bytes: usize,
    types: FxHashMap<&'a [u8], TypeId>,
    /// Each type id's name as written (what `types` is keyed by).
    raw_type_names: Vec<&'a [u8]>,
    index: RawIndex,
}

/// Where a scan of statements stopped.
enum Stop {
    /// At the first statement starting at or after the limit (this offset).
    Reached(usize),
    /// After the section's ENDSEC.
    EndSection,
}

/// DATA sections smaller than this per thread are scanned in one pass.
const MIN_CHUNK_BYTES: usize = 1 << 20;

impl<'a> Scanner<'a> {
    fn new(bytes: &'a [u8], options: &ReadOptions) -> Self {
        Scanner {
            bytes,
            pos: 0,
            max_depth: options.max_depth,
            max_instances: options.max_instances,
            max_string_bytes: options.max_string_bytes,
            types: FxHashMap::default(),
            raw_type_names: Vec::new(),
            // Instances take 40+ bytes in practice; reserving avoids regrowth copies.
            index: RawIndex {
                records: Vec::with_capacity((bytes.len() / 48).min(options.max_instances)),
                type_names: Vec::new(),
                chunks: 1,
            },
        }
    }

    fn skip(&mut self) {
        let rest = skip_ws(&self.bytes[self.pos..]);
        self.pos = self.bytes.len() - rest.len();
    }

    fn rest(&self) -> &'a [u8] {
        &self.bytes[self.pos..]
    }

    /// Consumes `word` followed by optional white space and `;`.
    fn keyword_statement(&mut self, word: &[u8]) -> bool {
        let save = self.pos;
        self.skip();
        if self.rest().starts_with(word) {
            self.pos += word.len();
            self.skip();
            if self.rest().first() == Some(&b';') {
                self.pos += 1;
                return true;
            }
        }
        self.pos = save;
        false
    }

    fn scan(mut self) -> Result<(Header, RawIndex), ScanError> {
        // A UTF-8 byte order mark is tolerated.
        if self.bytes.starts_with(b"\xEF\xBB\xBF") {
            self.pos = 3;
        }
        if !self.keyword_statement(b"ISO-10303-21") {
            self.skip();
            return Err((self.pos, StepErrorKind::NotStep, None));
        }
        if !self.keyword_statement(b"HEADER") {
            self.skip();
            return Err((self.pos, StepErrorKind::MissingHeader, None));
        }
        let header = self.scan_header()?;
        let mut sections = 0;
        loop {
            self.skip();
            if self.rest().is_empty() {
                if sections == 0 {
                    return Err((self.pos, StepErrorKind::MissingData, None));
                }
                break;
            }
            if self.keyword_statement(b"END-ISO-10303-21") {
                break;
            }
            if !self.data_section_start() {
                let kind = if sections == 0 {
                    StepErrorKind::MissingData
                } else {
                    StepErrorKind::Syntax(format!(
                        "expected DATA; or END-ISO-10303-21; at `{}`",
                        params::snippet(self.rest())
                    ))
                };
                return Err((self.pos, kind, None));
            }
            sections += 1;
            if sections > 1 || !self.scan_data_in_chunks() {
                self.scan_data()?;
            }
        }
        Ok((header, self.index))
    }

    fn scan_header(&mut self) -> Result<Header, ScanError> {
        let mut header = Header::default();
        let mut seen_schema = false;
        loop {
            self.skip();
            if self.keyword_statement(b"ENDSEC") {
                break;
            }
            let start = self.pos;
            let (after_name, name) = match params::keyword(self.rest()) {
                Ok(v) => v,
                Err(_) if self.rest().is_empty() => {
                    return Err((
                        start,
                        StepErrorKind::Truncated {
                            inside: "the HEADER section".into(),
                        },
                        None,
                    ));
                }
                Err(_) => {
                    let msg = format!(
                        "expected a header entity or ENDSEC; at `{}`",
                        params::snippet(self.rest())
                    );
                    return Err((start, StepErrorKind::Syntax(msg), None));
                }
            };
            let name = name.to_ascii_uppercase();
            if name == "DATA" {
                return Err((
                    start,
                    StepErrorKind::Syntax("the HEADER section has no ENDSEC;".into()),
                    None,
                ));
            }
            let list_start = self.bytes.len() - skip_ws(after_name).len();
            let end = self.statement_end(list_start, &name, None)?;
            let params = params::decode_list(&self.bytes[list_start..end], self.max_depth)
                .map_err(|(at, kind)| (list_start + at, kind, None))?;
            seen_schema |= name == "FILE_SCHEMA";
            header.absorb(&name, &params);
            self.pos = end + 1;
        }
        if !seen_schema {
            return Err((
                self.pos,
                StepErrorKind::MissingHeaderEntity("FILE_SCHEMA"),
                None,
            ));
        }
        Ok(header)
    }

    /// `DATA;` or the edition-3 form `DATA(...);`.
    fn data_section_start(&mut self) -> bool {
        let save = self.pos;
        if self.rest().starts_with(b"DATA") {
            self.pos += 4;
            self.skip();
            if self.rest().first() == Some(&b'(') {
                if let Ok(end) = self.statement_end(self.pos, "DATA", None) {
                    self.pos = end + 1;
                    return true;
                }
            } else if self.rest().first() == Some(&b';') {
                self.pos += 1;
                return true;
            }
        }
        self.pos = save;
        false
    }

    fn scan_data(&mut self) -> Result<(), ScanError> {
        self.scan_data_until(usize::MAX).map(|_| ())
    }

    /// The first DATA section scanned in parallel chunks, each starting after a `;` that is
    /// followed by `#`. Such a `;` may still be inside a string or comment, so chunks are
    /// joined in order from where the one before truly ended: a chunk that started there is
    /// kept, one that did not is scanned again from there. Every record therefore comes from
    /// a scan that started at a true statement boundary, and the index is exactly one pass's.
    /// Returns false, with nothing indexed, when a chunk meets an error (one pass then reports
    /// it where it is) or the section ends before the last chunk (more sections follow), or
    /// when the section is too small to be worth splitting.
    fn scan_data_in_chunks(&mut self) -> bool {
        let start = self.pos;
        let len = self.bytes.len() - start;
        let n = rayon::current_num_threads().min(len / MIN_CHUNK_BYTES);
        if n < 2 {
            return false;
        }
        let mut starts = vec![start];
        for k in 1..n {
            let nominal = (start + k * (len / n)).max(starts[k - 1]);
            match self.statement_start_after(nominal) {
                Some(p) => starts.push(p),
                None => break,
            }
        }
        let ends: Vec<usize> = starts.iter().skip(1).copied().chain([usize::MAX]).collect();
        let scan = |from: usize, until: usize| {
            let mut chunk = self.chunk_from(from, until.min(self.bytes.len()) - from);
            let stop = chunk.scan_data_until(until).ok()?;
            Some((chunk, stop))
        };
        let scanned: Vec<Option<(Scanner<'a>, Stop)>> = starts
            .par_iter()
            .zip(&ends)
            .map(|(&from, &until)| scan(from, until))
            .collect();
        let last = scanned.len() - 1;
        let mut joined: Vec<Scanner<'a>> = Vec::with_capacity(scanned.len());
        let mut at = start;
        for (k, chunk) in scanned.into_iter().enumerate() {
            let chunk = match chunk {
                Some(c) if starts[k] == at => c,
                _ => match scan(at, ends[k]) {
                    Some(c) => c,
                    None => return false,
                },
            };
            match chunk.1 {
                Stop::Reached(end) if k < last => at = end,
                Stop::EndSection if k == last => {}
                _ => return false,
            }
            joined.push(chunk.0);
        }
        let count: usize = joined.iter().map(|c| c.index.records.len()).sum();
        if count > self.max_instances {
            return false;
        }
        self.index.records.reserve(count);
        for chunk in joined {
            // Chunk type ids to the file's, in order of first use as one pass assigns them.
            let ids: Vec<TypeId> = chunk
                .raw_type_names
                .iter()
                .map(|raw| self.intern(raw))
                .collect();
            self.index
                .records
                .extend(chunk.index.records.into_iter().map(|r| Record {
                    type_id: ids[r.type_id as usize],
                    ..r
                }));
            self.pos = chunk.pos;
        }
        self.index.chunks = starts.len();
        true
    }

    /// The offset just after the first `;` at or after `from` that white space and `#` follow.
    fn statement_start_after(&self, mut from: usize) -> Option<usize> {
        loop {
            let p = from + memchr::memchr(b';', &self.bytes[from..])? + 1;
            if self.bytes[p..].trim_ascii_start().first() == Some(&b'#') {
                return Some(p);
            }
            from = p;
        }
    }

    /// A scanner of the same file from `from`, for a chunk of about `len` bytes.
    fn chunk_from(&self, from: usize, len: usize) -> Scanner<'a> {
        Scanner {
            bytes: self.bytes,
            pos: from,
            max_depth: self.max_depth,
            max_instances: self.max_instances,
            max_string_bytes: self.max_string_bytes,
            types: FxHashMap::default(),
            raw_type_names: Vec::new(),
            index: RawIndex {
                records: Vec::with_capacity((len / 48).min(self.max_instances)),
                type_names: Vec::new(),
                chunks: 1,
            },
        }
    }

    /// Scans statements until ENDSEC or until the next statement would start at or after
    /// `until`.
    fn scan_data_until(&mut self, until: usize) -> Result<Stop, ScanError> {
        loop {
            if self.pos >= until {
                return Ok(Stop::Reached(self.pos));
            }
            self.skip();
            if self.keyword_statement(b"ENDSEC") {
                return Ok(Stop::EndSection);
            }
            let start = self.pos;
            let rest = self.rest();
            if rest.is_empty() {
                return Err((
                    start,
                    StepErrorKind::Truncated {
                        inside: "the DATA section".into(),
                    },
                    None,
                ));
            }
            if rest[0] != b'#' {
                let msg = format!("expected `#id=` or ENDSEC; at `{}`", params::snippet(rest));
                return Err((start, StepErrorKind::Syntax(msg), None));
            }
            let digits = rest[1..].iter().take_while(|c| c.is_ascii_digit()).count();
            let id = std::str::from_utf8(&rest[1..1 + digits])
                .ok()
                .and_then(|d| d.parse::<u64>().ok());
            let Some(id) = id else {
                let msg = format!("bad entity id at `{}`", params::snippet(rest));
                return Err((start, StepErrorKind::Syntax(msg), None));
            };
            self.pos += 1 + digits;
            self.skip();
            if self.rest().first() != Some(&b'=') {
                let msg = format!("expected `=` after #{id}");
                return Err((self.pos, StepErrorKind::Syntax(msg), Some(id)));
            }
            self.pos += 1;
            self.skip();
            let type_id = if self.rest().first() == Some(&b'(') {
                // Complex instance `#id=(A(...)B(...));`: indexed under an empty type name.
                self.intern(b"")
            } else {
                match params::keyword(self.rest()) {
                    Ok((after, name)) => {
                        let type_id = self.intern(name.as_bytes());
                        self.pos = self.bytes.len() - skip_ws(after).len();
                        type_id
                    }
                    Err(_) if self.rest().is_empty() => {
                        let inside = format!("entity #{id}");
                        return Err((start, StepErrorKind::Truncated { inside }, Some(id)));
                    }
                    Err(_) => {
                        let msg = format!(
                            "expected an entity type name at `{}`",
                            params::snippet(self.rest())
                        );
                        return Err((self.pos, StepErrorKind::Syntax(msg), Some(id)));
                    }
                }
            };
            if self.rest().first() != Some(&b'(') {
                let kind = if self.rest().is_empty() {
                    StepErrorKind::Truncated {
                        inside: format!("entity #{id}"),
                    }
                } else {
                    StepErrorKind::Syntax(format!("expected `(` after the type name of #{id}"))
                };
                return Err((self.pos, kind, Some(id)));
            }
            let list_start = self.pos;
            let end = self.statement_end(list_start, "", Some((id, start)))?;
            let close = self.bytes[list_start..end].trim_ascii_end();
            if close.last() != Some(&b')') {
                let msg = format!("the parameter list of #{id} is not closed before `;`");
                return Err((end, StepErrorKind::Syntax(msg), Some(id)));
            }
            if self.index.records.len() >= self.max_instances {
                let kind = StepErrorKind::TooManyInstances {
                    limit: self.max_instances,
                };
                return Err((start, kind, Some(id)));
            }
            self.index.records.push(Record {
                id,
                type_id,
                start,
                params: (list_start, list_start + close.len()),
            });
            self.pos = end + 1;
        }
    }

    fn intern(&mut self, name: &'a [u8]) -> TypeId {
        if let Some(&t) = self.types.get(name) {
            return t;
        }
        let t = self.index.type_names.len() as TypeId;
        self.index
            .type_names
            .push(String::from_utf8_lossy(name).to_ascii_uppercase());
        self.raw_type_names.push(name);
        self.types.insert(name, t);
        t
    }

    /// Offset of the `;` ending the statement that starts at `from`,
    /// skipping strings and comments.
    fn statement_end(
        &self,
        from: usize,
        what: &str,
        entity: Option<(u64, usize)>,
    ) -> Result<usize, ScanError> {
        let bytes = self.bytes;
        let mut at = from;
        let truncated = || {
            let (inside, start, id) = match entity {
                Some((id, start)) => (format!("entity #{id}"), start, Some(id)),
                None => (format!("header entity {what}"), from, None),
            };
            (start, StepErrorKind::Truncated { inside }, id)
        };
        loop {
            let Some(p) = memchr::memchr3(b';', b'\'', b'/', &bytes[at..]) else {
                return Err(truncated());
            };
            let i = at + p;
            match bytes[i] {
                b';' => return Ok(i),
                b'\'' => match super::strings::string_end(&bytes[i + 1..]) {
                    Some(end) if end > self.max_string_bytes => {
                        let kind = StepErrorKind::StringTooLong {
                            limit: self.max_string_bytes,
                        };
                        return Err((i, kind, entity.map(|(id, _)| id)));
                    }
                    Some(end) => at = i + 1 + end + 1,
                    None => return Err(truncated()),
                },
                _ => {
                    if bytes.get(i + 1) == Some(&b'*') {
                        let Some(q) = memchr::memmem::find(&bytes[i + 2..], b"*/") else {
                            return Err(truncated());
                        };
                        at = i + 2 + q + 2;
                    } else {
                        at = i + 1;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
