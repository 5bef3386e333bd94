//! A fixed-capacity string for golden lines, row labels and arguments.

/// A fixed-capacity string for golden lines and row labels (`core::fmt::Write`; writing
/// past `CAP` bytes is a `fmt::Error`, never a panic).
#[derive(Debug)]
pub struct Text<const CAP: usize> {
    buf: [u8; CAP],
    len: usize,
}

impl<const CAP: usize> Text<CAP> {
    /// Empty text.
    pub const fn new() -> Self {
        Self {
            buf: [0; CAP],
            len: 0,
        }
    }

    /// Empties the text (keeps the buffer).
    #[inline]
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// The text written so far.
    #[inline]
    pub fn as_str(&self) -> &str {
        core::str::from_utf8(&self.buf[..self.len]).unwrap_or("<utf8>")
    }
}

impl<const CAP: usize> Default for Text<CAP> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const CAP: usize> core::fmt::Write for Text<CAP> {
    #[inline]
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let end = self.len + s.len();
        let dst = self.buf.get_mut(self.len..end).ok_or(core::fmt::Error)?;
        dst.copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}
