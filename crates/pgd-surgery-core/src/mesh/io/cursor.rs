//! A binary mesh file's bytes read from a cursor: numbers as bytes in the file's byte order,
//! and the words of text binary formats still write (section names, counts). Errors name the
//! byte the cursor is at, lines meaning nothing among binary numbers.

use super::ImportError;

pub struct Cursor<'a> {
    file: &'a str,
    bytes: &'a [u8],
    at: usize,
    little_endian: bool,
}

impl<'a> Cursor<'a> {
    pub fn new(file: &'a str, bytes: &'a [u8], little_endian: bool) -> Self {
        Self {
            file,
            bytes,
            at: 0,
            little_endian,
        }
    }

    /// The cursor moved on to byte `at` of the file.
    pub fn moved_to(mut self, at: usize) -> Self {
        self.at = at;
        self
    }

    pub fn set_little_endian(&mut self, little_endian: bool) {
        self.little_endian = little_endian;
    }

    fn rest(&self) -> &'a [u8] {
        &self.bytes[self.at.min(self.bytes.len())..]
    }

    /// The next `N` bytes, turned into little-endian order.
    pub fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N], ImportError> {
        let Some(bytes) = self.rest().get(..N) else {
            return Err(self.error(format!("unexpected end of file; expected {what}")));
        };
        self.at += N;
        let mut out: [u8; N] = bytes.try_into().expect("N bytes");
        if !self.little_endian {
            out.reverse();
        }
        Ok(out)
    }

    /// The next word of text after white space, and the line end right after it, where
    /// binary data may start.
    pub fn word(&mut self, what: &str) -> Result<&'a str, ImportError> {
        let rest = self.rest();
        let Some(start) = rest.iter().position(|b| !b.is_ascii_whitespace()) else {
            return Err(self.error(format!("unexpected end of file; expected {what}")));
        };
        let length = (rest[start..].iter())
            .position(|b| b.is_ascii_whitespace())
            .unwrap_or(rest.len() - start);
        self.at += start + length;
        let word = std::str::from_utf8(&rest[start..start + length])
            .map_err(|_| self.error(format!("expected {what}, found bytes that are not text")))?;
        self.end_line();
        Ok(word)
    }

    /// A number written as text.
    pub fn parse<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, ImportError> {
        let word = self.word(what)?;
        (word.parse()).map_err(|_| self.error(format!("expected {what}, found '{word}'")))
    }

    fn end_line(&mut self) {
        let rest = self.rest();
        if rest.starts_with(b"\r\n") {
            self.at += 2;
        } else if rest.starts_with(b"\n") {
            self.at += 1;
        }
    }

    /// Whether the next word is `keyword`; if so, it is passed.
    pub fn passes(&mut self, keyword: &str) -> bool {
        let rest = self.rest();
        let start = (rest.iter().position(|b| !b.is_ascii_whitespace())).unwrap_or(rest.len());
        let found = rest[start..].starts_with(keyword.as_bytes())
            && (rest.get(start + keyword.len())).is_none_or(u8::is_ascii_whitespace);
        if found {
            self.at += start + keyword.len();
            self.end_line();
        }
        found
    }

    /// The rest of the line as text.
    pub fn rest_of_line(&mut self) -> String {
        let rest = self.rest();
        let length = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        self.at += length;
        String::from_utf8_lossy(&rest[..length]).trim().to_owned()
    }

    /// Passes everything up to and including `keyword`.
    pub fn skip_past(&mut self, keyword: &str) -> Result<(), ImportError> {
        let found = (self.rest().windows(keyword.len())).position(|w| w == keyword.as_bytes());
        match found {
            Some(k) => {
                self.at += k + keyword.len();
                Ok(())
            }
            None => Err(self.error(format!("unexpected end of file; expected {keyword}"))),
        }
    }

    /// Whether only white space is left.
    pub fn at_end(&self) -> bool {
        self.rest().iter().all(u8::is_ascii_whitespace)
    }

    pub fn error(&self, message: String) -> ImportError {
        ImportError::Binary {
            file: self.file.to_owned(),
            byte: self.at,
            message,
        }
    }
}
