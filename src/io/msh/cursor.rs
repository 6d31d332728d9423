//! A reading position in an MSH file that reads numbers either as ASCII tokens or as binary values.
//!
//! The same section parsers serve ASCII and binary files: they ask for an `int`, a `size`
//! (`size_t`) or a `double`, and the cursor reads a token or the bytes, depending on whether the
//! current section is binary. Errors carry the line while no binary data has been passed, then the
//! byte offset.

use std::str::FromStr;

use crate::io::ParseError;

pub struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// 1-based line of `pos`; meaningful until the first binary section.
    line: usize,
    /// Numbers are read as binary values (inside the binary sections of a binary file).
    pub binary: bool,
    /// The file is big-endian.
    pub swap: bool,
    /// Bytes of a `size_t` (the MSH data-size).
    pub size_t: usize,
    seen_binary: bool,
}

fn is_space(b: u8) -> bool {
    b.is_ascii_whitespace()
}

impl<'a> Cursor<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Cursor { bytes, pos: 0, line: 1, binary: false, swap: false, size_t: 8, seen_binary: false }
    }

    /// An error at the current position: its line, or its byte offset once binary data was passed.
    pub fn error(&self, message: impl Into<String>) -> ParseError {
        if self.seen_binary || self.binary {
            ParseError::at_byte(self.pos as u64, message)
        } else {
            ParseError::at_line(self.line, message)
        }
    }

    pub fn at_end(&mut self) -> bool {
        self.skip_space();
        self.pos >= self.bytes.len()
    }

    pub fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    /// How many items of at least `min_bytes` each can still follow: caps allocations by counts
    /// read from the file.
    pub fn capacity(&self, count: u64, min_bytes: usize) -> usize {
        let fit = self.remaining() / min_bytes.max(1);
        usize::try_from(count).map_or(fit, |c| c.min(fit))
    }

    fn skip_space(&mut self) {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !is_space(b) {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
    }

    /// The next whitespace-separated token (text mode).
    pub fn token(&mut self, what: &str) -> Result<&'a str, ParseError> {
        self.skip_space();
        let start = self.pos;
        while self.bytes.get(self.pos).is_some_and(|&b| !is_space(b)) {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.error(format!("expected {what}, found the end of the file")));
        }
        std::str::from_utf8(&self.bytes[start..self.pos])
            .map_err(|_| self.error(format!("expected {what}, found non-text bytes")))
    }

    /// The next token parsed as a `T` (text mode).
    pub fn parse<T: FromStr>(&mut self, what: &str) -> Result<T, ParseError> {
        let token = self.token(what)?;
        token.parse().map_err(|_| self.error(format!("expected {what}, found '{}'", clip(token))))
    }

    /// The rest of the current line, without its line break, and move to the next line.
    pub fn rest_of_line(&mut self) -> &'a str {
        let start = self.pos;
        while self.bytes.get(self.pos).is_some_and(|&b| b != b'\n') {
            self.pos += 1;
        }
        let text = std::str::from_utf8(&self.bytes[start..self.pos]).unwrap_or("");
        if self.pos < self.bytes.len() {
            self.pos += 1;
            self.line += 1;
        }
        text.trim_end_matches('\r')
    }

    /// Expect the given keyword (e.g. `$EndNodes`) as the next token.
    pub fn expect(&mut self, keyword: &str) -> Result<(), ParseError> {
        let token = self.token(keyword)?;
        if token != keyword {
            return Err(self.error(format!("expected {keyword}, found '{}'", clip(token))));
        }
        Ok(())
    }

    /// Move past the line that starts with `keyword` (to skip an unknown section).
    pub fn skip_past(&mut self, keyword: &str) -> Result<(), ParseError> {
        let needle = keyword.as_bytes();
        let found = self.bytes[self.pos..].windows(needle.len()).position(|w| w == needle);
        let Some(offset) = found else {
            return Err(self.error(format!("{keyword} is missing")));
        };
        if !self.seen_binary {
            self.line += self.bytes[self.pos..self.pos + offset].iter().filter(|&&b| b == b'\n').count();
        }
        self.pos += offset + needle.len();
        Ok(())
    }

    /// Switch between text and binary numbers; binary data starts right after the line break.
    pub fn set_binary(&mut self, binary: bool) {
        if binary && !self.binary {
            self.rest_of_line();
            self.seen_binary = true;
        }
        self.binary = binary;
    }

    /// `n` raw bytes.
    pub fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], ParseError> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(self.error(format!("file truncated: expected {what}")));
        };
        let slice = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(slice)
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], ParseError> {
        let mut a = [0; N];
        a.copy_from_slice(self.take(N, what)?);
        if self.swap {
            a.reverse();
        }
        Ok(a)
    }

    /// An `int` (4 bytes in binary).
    pub fn int(&mut self, what: &str) -> Result<i32, ParseError> {
        if self.binary {
            Ok(i32::from_le_bytes(self.array(what)?))
        } else {
            self.parse(what)
        }
    }

    /// A `size_t` (data-size bytes in binary).
    pub fn size(&mut self, what: &str) -> Result<u64, ParseError> {
        if !self.binary {
            return self.parse(what);
        }
        if self.size_t == 4 {
            Ok(u32::from_le_bytes(self.array(what)?).into())
        } else {
            Ok(u64::from_le_bytes(self.array(what)?))
        }
    }

    /// A non-negative `int` or `size_t` count.
    pub fn count(&mut self, what: &str, size_t: bool) -> Result<u64, ParseError> {
        if size_t {
            return self.size(what);
        }
        let n = self.int(what)?;
        u64::try_from(n).map_err(|_| self.error(format!("{what} is negative ({n})")))
    }

    /// A `double` (8 bytes in binary).
    pub fn double(&mut self, what: &str) -> Result<f64, ParseError> {
        if self.binary {
            Ok(f64::from_le_bytes(self.array(what)?))
        } else {
            self.parse(what)
        }
    }
}

/// At most 40 characters of a token, for error messages.
fn clip(s: &str) -> String {
    s.chars().take(40).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::Location;

    #[test]
    fn tokens_lines_and_errors() {
        let mut c = Cursor::new(b"$Nodes\n 3 x\n\"a b\" rest\n");
        assert_eq!(c.token("section").unwrap(), "$Nodes");
        assert_eq!(c.parse::<u64>("count").unwrap(), 3);
        let e = c.parse::<u64>("count").unwrap_err();
        assert_eq!(e.at, Location::Line(2));
        assert!(e.message.contains("found 'x'"), "{e}");
        c.rest_of_line();
        assert_eq!(c.rest_of_line(), "\"a b\" rest");
        assert!(c.at_end());
        assert_eq!(c.token("tag").unwrap_err().at, Location::Line(4));
    }

    #[test]
    fn binary_values_and_truncation() {
        let mut bytes = b"$Nodes\n".to_vec();
        bytes.extend_from_slice(&7i32.to_le_bytes());
        bytes.extend_from_slice(&1.5f64.to_le_bytes());
        bytes.extend_from_slice(&[1, 2]);
        let mut c = Cursor::new(&bytes);
        c.token("section").unwrap();
        c.set_binary(true);
        assert_eq!(c.int("tag").unwrap(), 7);
        assert_eq!(c.double("x").unwrap(), 1.5);
        let e = c.size("count").unwrap_err();
        assert_eq!(e.at, Location::Byte(19));
        assert_eq!(c.capacity(u64::MAX, 1), 2);
    }

    #[test]
    fn big_endian_values() {
        let mut bytes = b"x\n".to_vec();
        bytes.extend_from_slice(&(-2i32).to_be_bytes());
        let mut c = Cursor::new(&bytes);
        c.token("x").unwrap();
        c.swap = true;
        c.set_binary(true);
        assert_eq!(c.int("tag").unwrap(), -2);
    }
}
