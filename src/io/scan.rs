//! What every surface reader needs: text tokens with line numbers, bounds-checked binary
//! reads with byte offsets, checked counts and indices, and the final clean-up of a surface.

use std::borrow::Cow;
use std::str::FromStr;

use super::ParseError;
use crate::surface::Surface;

/// The file as text. Bytes that are not UTF-8 become U+FFFD (they can only matter in names and
/// comments; anywhere else the token that holds them fails to parse, with its line).
pub(crate) fn text(bytes: &[u8]) -> Cow<'_, str> {
    String::from_utf8_lossy(bytes)
}

/// The non-empty lines of `text` with their 1-based numbers, trimmed, each cut at `comment`.
pub(crate) fn content_lines(text: &str, comment: Option<char>) -> impl Iterator<Item = (usize, &str)> + '_ {
    text.lines().enumerate().filter_map(move |(i, line)| {
        let line = match comment.and_then(|c| line.find(c)) {
            Some(end) => &line[..end],
            None => line,
        };
        let line = line.trim();
        (!line.is_empty()).then_some((i + 1, line))
    })
}

/// Parse a real number; Fortran `D` exponents (`1.0D+00`) are accepted too.
pub(crate) fn parse_f64(token: &str, line: usize, what: &str) -> Result<f64, ParseError> {
    token
        .parse()
        .or_else(|_| token.replace(['d', 'D'], "e").parse())
        .map_err(|_| ParseError::at_line(line, format!("bad number '{token}' for {what}")))
}

/// Parse an integer of type `T` (out of `T`'s range is a bad number too).
pub(crate) fn parse_int<T: FromStr>(token: &str, line: usize, what: &str) -> Result<T, ParseError> {
    token.parse().map_err(|_| ParseError::at_line(line, format!("bad integer '{token}' for {what}")))
}

/// The first three reals of a line (`what` = e.g. "a vertex"); what follows them is ignored.
pub(crate) fn line_point(text: &str, line: usize, what: &str) -> Result<[f64; 3], ParseError> {
    let mut p = [0.0; 3];
    let mut tokens = text.split_whitespace();
    for (i, coordinate) in p.iter_mut().enumerate() {
        let token = tokens
            .next()
            .ok_or_else(|| ParseError::at_line(line, format!("{what} needs 3 coordinates, found {i}")))?;
        *coordinate = parse_f64(token, line, &format!("a coordinate of {what}"))?;
    }
    Ok(p)
}

/// The largest number of points or triangles a surface can hold (indices are `u32`).
pub(crate) const MAX_COUNT: usize = u32::MAX as usize;

/// Check a count read from a file against what `u32` indices can address.
pub(crate) fn check_count(count: u64, what: &str) -> Result<usize, String> {
    usize::try_from(count)
        .ok()
        .filter(|&c| c <= MAX_COUNT)
        .ok_or_else(|| format!("{what} count {count} exceeds the supported maximum {MAX_COUNT}"))
}

/// Capacity to reserve for `count` items of at least `item_bytes` bytes each when only
/// `remaining` bytes are left: a lying count cannot make us allocate more than the file holds.
pub(crate) fn capacity(count: usize, remaining: usize, item_bytes: usize) -> usize {
    count.min(remaining / item_bytes.max(1))
}

/// The 0-based vertex index for `value`, where the file numbers vertices from `base`
/// (0 or 1); `None` when it is not one of the `count` vertices.
pub(crate) fn vertex_index(value: i64, base: i64, count: usize) -> Option<u32> {
    let index = u64::try_from(value.checked_sub(base)?).ok()?;
    (index < count as u64).then_some(index as u32)
}

/// The message for a vertex reference that [`vertex_index`] rejected.
pub(crate) fn bad_vertex(value: i64, count: usize, numbering: &str) -> String {
    format!("vertex index {value} out of range: the file has {count} vertices, numbered {numbering}")
}

/// Last step of every reader: drop the points no triangle uses, and refuse an empty surface.
pub(crate) fn finish(mut surface: Surface) -> Result<Surface, ParseError> {
    if surface.triangles.is_empty() {
        return Err(ParseError::file("the file contains no triangles"));
    }
    surface.remove_unused_points();
    Ok(surface)
}

/// Whitespace-separated tokens of a text with their 1-based line numbers; text from the
/// comment character to the end of the line is skipped.
#[derive(Clone, Debug)]
pub(crate) struct Tokens<'a> {
    rest: &'a str,
    line: usize,
    last_token_line: usize,
    comment: Option<char>,
}

impl<'a> Tokens<'a> {
    pub fn new(text: &'a str, comment: Option<char>) -> Self {
        Tokens { rest: text, line: 1, last_token_line: 1, comment }
    }

    /// The line of the last token returned: where an unexpected end of file is reported.
    pub fn line(&self) -> usize {
        self.last_token_line
    }

    /// Skip whitespace and comments, counting lines.
    fn skip_blank(&mut self) {
        loop {
            let trimmed = self.rest.trim_start_matches(|c: char| c.is_whitespace() && c != '\n');
            if let Some(after) = trimmed.strip_prefix('\n') {
                self.line += 1;
                self.rest = after;
            } else if self.comment.is_some_and(|c| trimmed.starts_with(c)) {
                self.rest = &trimmed[trimmed.find('\n').unwrap_or(trimmed.len())..];
            } else {
                self.rest = trimmed;
                return;
            }
        }
    }

    pub fn peek(&mut self) -> Option<(usize, &'a str)> {
        self.skip_blank();
        let end = self.rest.find(char::is_whitespace).unwrap_or(self.rest.len());
        let end = match self.comment.and_then(|c| self.rest[..end].find(c)) {
            Some(comment_start) => comment_start,
            None => end,
        };
        (end > 0).then(|| (self.line, &self.rest[..end]))
    }

    pub fn next_token(&mut self) -> Option<(usize, &'a str)> {
        let (line, token) = self.peek()?;
        self.rest = &self.rest[token.len()..];
        self.last_token_line = line;
        Some((line, token))
    }

    /// The next token, or an error naming `what` was expected at the end of the file.
    pub fn require(&mut self, what: &str) -> Result<(usize, &'a str), ParseError> {
        self.next_token().ok_or_else(|| self.end_of_file(what))
    }

    fn end_of_file(&self, what: &str) -> ParseError {
        ParseError::at_line(self.line(), format!("unexpected end of file: expected {what}"))
    }

    /// The next token, which must be `keyword` (ASCII case-insensitive).
    pub fn keyword(&mut self, keyword: &str) -> Result<usize, ParseError> {
        match self.next_token() {
            Some((line, token)) if token.eq_ignore_ascii_case(keyword) => Ok(line),
            Some((line, token)) => {
                Err(ParseError::at_line(line, format!("expected '{keyword}', found '{token}'")))
            }
            None => Err(self.end_of_file(&format!("'{keyword}'"))),
        }
    }

    pub fn real(&mut self, what: &str) -> Result<f64, ParseError> {
        let (line, token) = self.require(what)?;
        parse_f64(token, line, what)
    }

    pub fn int<T: FromStr>(&mut self, what: &str) -> Result<T, ParseError> {
        let (line, token) = self.require(what)?;
        parse_int(token, line, what)
    }

    /// A count of points or triangles: a non-negative integer `u32` indices can address.
    pub fn count(&mut self, what: &str) -> Result<usize, ParseError> {
        let (line, token) = self.require(&format!("{what} count"))?;
        let count: u64 = parse_int(token, line, &format!("{what} count"))?;
        check_count(count, what).map_err(|message| ParseError::at_line(line, message))
    }

    /// Three reals: a point.
    pub fn point(&mut self, what: &str) -> Result<[f64; 3], ParseError> {
        Ok([self.real(what)?, self.real(what)?, self.real(what)?])
    }

    /// The rest of the current line (comment included), trimmed; the tokens go on at the next
    /// line. Must follow `next_token`/`expect` on that line.
    pub fn rest_of_line(&mut self) -> &'a str {
        let end = self.rest.find('\n').unwrap_or(self.rest.len());
        let rest = &self.rest[..end];
        self.rest = &self.rest[end..];
        rest.trim()
    }

    /// Bytes of text not yet read: a bound for the number of items still to come.
    pub fn remaining(&self) -> usize {
        self.rest.len()
    }
}

/// Bounds-checked reads from a binary file in a chosen byte order; errors carry the offset.
#[derive(Clone, Debug)]
pub(crate) struct ByteReader<'a> {
    data: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl<'a> ByteReader<'a> {
    pub fn new(data: &'a [u8], big_endian: bool) -> Self {
        ByteReader { data, pos: 0, big_endian }
    }

    pub fn pos(&self) -> usize {
        self.pos
    }

    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    pub fn at_end(&self) -> bool {
        self.pos == self.data.len()
    }

    /// An error at the current offset.
    pub fn error(&self, message: impl Into<String>) -> ParseError {
        ParseError::at_byte(self.pos as u64, message)
    }

    /// Move to `pos` (at most the file length).
    pub fn seek(&mut self, pos: u64, what: &str) -> Result<(), ParseError> {
        match usize::try_from(pos) {
            Ok(p) if p <= self.data.len() => {
                self.pos = p;
                Ok(())
            }
            _ => Err(self.error(format!(
                "{what} points to byte {pos}, beyond the end of the file ({} bytes)",
                self.data.len()
            ))),
        }
    }

    /// The next `n` bytes.
    pub fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], ParseError> {
        if n > self.remaining() {
            return Err(
                self.error(format!("file ends inside {what}: {n} bytes needed, {} left", self.remaining()))
            );
        }
        let bytes = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(bytes)
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], ParseError> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N, what)?);
        if self.big_endian {
            a.reverse();
        }
        Ok(a)
    }

    pub fn u32(&mut self, what: &str) -> Result<u32, ParseError> {
        self.array(what).map(u32::from_le_bytes)
    }

    pub fn i32(&mut self, what: &str) -> Result<i32, ParseError> {
        self.array(what).map(i32::from_le_bytes)
    }

    pub fn i64(&mut self, what: &str) -> Result<i64, ParseError> {
        self.array(what).map(i64::from_le_bytes)
    }

    pub fn f32(&mut self, what: &str) -> Result<f32, ParseError> {
        self.array(what).map(f32::from_le_bytes)
    }

    pub fn f64(&mut self, what: &str) -> Result<f64, ParseError> {
        self.array(what).map(f64::from_le_bytes)
    }
}

/// Test helpers shared by the readers' tests.
#[cfg(test)]
pub(crate) mod testing {
    use super::super::{Location, ParseError};
    use crate::surface::Surface;

    /// Assert that `parse` rejects `bytes` at `at` with a message that contains `needle`.
    #[track_caller]
    pub fn assert_error(
        parse: fn(&[u8]) -> Result<Surface, ParseError>,
        bytes: impl AsRef<[u8]>,
        at: Location,
        needle: &str,
    ) {
        match parse(bytes.as_ref()) {
            Ok(s) => panic!("accepted ({} triangles), expected an error with '{needle}'", s.triangles.len()),
            Err(e) => {
                assert!(e.message.contains(needle), "'{e}' does not say '{needle}'");
                assert_eq!(e.at, at, "{e}");
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_count_lines_and_skip_comments() {
        let mut t = Tokens::new("a b # c d\n\n  e#f\r\ng", Some('#'));
        let all: Vec<_> = std::iter::from_fn(|| t.next_token()).collect();
        assert_eq!(all, vec![(1, "a"), (1, "b"), (3, "e"), (4, "g")]);
        let e = t.require("a vertex").unwrap_err();
        assert_eq!(e.at, super::super::Location::Line(4));
        assert!(e.message.contains("expected a vertex"), "{e}");
    }

    #[test]
    fn numbers_and_counts_are_checked() {
        assert_eq!(parse_f64("1.5D+01", 1, "x").unwrap(), 15.0);
        assert!(parse_f64("1.5q", 7, "x").unwrap_err().message.contains("'1.5q'"));
        let mut t = Tokens::new("99999999999 -1 12", None);
        assert!(t.count("vertex").unwrap_err().message.contains("exceeds"));
        assert!(t.count("vertex").is_err());
        assert_eq!(t.count("vertex").unwrap(), 12);
        assert_eq!(vertex_index(3, 1, 3), Some(2));
        assert_eq!(vertex_index(0, 1, 3), None);
        assert_eq!(vertex_index(i64::MIN, 1, 3), None);
        assert_eq!(capacity(1 << 40, 100, 10), 10);
    }

    #[test]
    fn byte_reader_reports_offsets_and_byte_order() {
        let mut r = ByteReader::new(&[0, 0, 0, 7, 1], true);
        assert_eq!(r.u32("count").unwrap(), 7);
        let e = r.u32("count").unwrap_err();
        assert_eq!(e.at, super::super::Location::Byte(4));
        assert!(e.message.contains("4 bytes needed, 1 left"), "{e}");
        assert!(r.seek(6, "next keyword").is_err());
    }
}
