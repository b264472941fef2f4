//! Tokenizer for Netpbm-style text headers (PGM, PFM).

use std::str::FromStr;

pub(crate) struct HeaderReader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> HeaderReader<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, pos: 0 }
    }

    /// Next token, skipping whitespace and `#` comments (which run to the end of the line).
    pub(crate) fn token(&mut self) -> Option<&'a [u8]> {
        loop {
            match self.bytes.get(self.pos)? {
                c if c.is_ascii_whitespace() => self.pos += 1,
                b'#' => {
                    while self.bytes.get(self.pos).is_some_and(|&c| c != b'\n' && c != b'\r') {
                        self.pos += 1;
                    }
                }
                _ => break,
            }
        }
        let start = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|&c| !c.is_ascii_whitespace() && c != b'#')
        {
            self.pos += 1;
        }
        self.bytes.get(start..self.pos)
    }

    /// Next token parsed as `T`; `what` names the field in the error.
    pub(crate) fn number<T: FromStr>(&mut self, what: &str) -> Result<T, String> {
        let token = self.token().ok_or_else(|| format!("header ends before the {what}"))?;
        std::str::from_utf8(token)
            .ok()
            .and_then(|t| t.parse().ok())
            .ok_or_else(|| format!("bad {what} '{}' in header", String::from_utf8_lossy(token)))
    }

    /// Consumes the single whitespace byte that ends the header and returns the raster.
    pub(crate) fn raster(self) -> Result<&'a [u8], String> {
        match self.bytes.get(self.pos) {
            Some(c) if c.is_ascii_whitespace() => Ok(self.bytes.get(self.pos + 1..).unwrap_or(&[])),
            _ => Err("header is not followed by a single whitespace byte".into()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_comments_and_raster() {
        let mut r = HeaderReader::new(b"P5\n# made by hand\n3 2 # size\n65535\n\x01\x02");
        assert_eq!(r.token(), Some(&b"P5"[..]));
        assert_eq!(r.number::<u32>("width"), Ok(3));
        assert_eq!(r.number::<u32>("height"), Ok(2));
        assert_eq!(r.number::<u32>("maxval"), Ok(65535));
        assert_eq!(r.raster(), Ok(&b"\x01\x02"[..]));

        let mut r = HeaderReader::new(b"P5 -3");
        r.token();
        assert!(r.number::<u32>("width").is_err());
        assert!(r.number::<u32>("height").is_err());
        let mut r = HeaderReader::new(b"Pf 1 1 -1.0");
        for _ in 0..4 {
            r.token();
        }
        assert!(r.raster().is_err());
    }
}
