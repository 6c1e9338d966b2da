//! Whitespace-separated tokens with their line numbers, for text mesh formats whose errors
//! must say where in the file they are.

use std::str::FromStr;

use super::ImportError;

pub struct Tokens<'a> {
    file: &'a str,
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    current: std::vec::IntoIter<&'a str>,
    line: usize,
    offset: usize,
}

impl<'a> Tokens<'a> {
    pub fn new(file: &'a str, text: &'a str) -> Self {
        Self::from_line(file, text, 1)
    }

    /// Tokens of `text`, whose first line is line `first_line` of the file.
    pub fn from_line(file: &'a str, text: &'a str, first_line: usize) -> Self {
        Self {
            file,
            lines: text.lines().enumerate(),
            current: Vec::new().into_iter(),
            line: first_line - 1,
            offset: first_line - 1,
        }
    }

    /// An error at the current line.
    pub fn error(&self, message: impl Into<String>) -> ImportError {
        ImportError::Syntax {
            file: self.file.to_owned(),
            line: self.line,
            message: message.into(),
        }
    }

    /// The next token, or an error naming what was expected at the end of the file.
    pub fn next(&mut self, expected: &str) -> Result<&'a str, ImportError> {
        loop {
            if let Some(token) = self.current.next() {
                return Ok(token);
            }
            match self.lines.next() {
                Some((i, line)) => {
                    self.line = self.offset + i + 1;
                    self.current = line.split_whitespace().collect::<Vec<_>>().into_iter();
                }
                None => {
                    return Err(self.error(format!("unexpected end of file; expected {expected}")));
                }
            }
        }
    }

    /// The next token, left to be read.
    pub fn peek(&mut self) -> Option<&'a str> {
        loop {
            if let Some(&token) = self.current.as_slice().first() {
                return Some(token);
            }
            let (i, line) = self.lines.next()?;
            self.line = self.offset + i + 1;
            self.current = line.split_whitespace().collect::<Vec<_>>().into_iter();
        }
    }

    /// The rest of the current line as one string, then moves to the next line.
    pub fn rest_of_line(&mut self) -> String {
        let rest: Vec<&str> = self.current.by_ref().collect();
        rest.join(" ")
    }

    /// Parses the next token as `T`, naming `what` in the error.
    pub fn parse<T: FromStr>(&mut self, what: &str) -> Result<T, ImportError> {
        let token = self.next(what)?;
        token
            .parse()
            .map_err(|_| self.error(format!("expected {what}, found '{token}'")))
    }

    /// Requires the next token to be `keyword`.
    pub fn expect(&mut self, keyword: &str) -> Result<(), ImportError> {
        let token = self.next(keyword)?;
        if token == keyword {
            Ok(())
        } else {
            Err(self.error(format!("expected '{keyword}', found '{token}'")))
        }
    }

    /// Skips tokens up to and including `keyword`.
    pub fn skip_past(&mut self, keyword: &str) -> Result<(), ImportError> {
        while self.next(keyword)? != keyword {}
        Ok(())
    }
}
