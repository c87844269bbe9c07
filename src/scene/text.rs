//! Text files as input: unreadable or non-UTF-8 files are input errors naming the file.
use crate::error::InputError;
use std::path::Path;

/// Reads a text file; unreadable or non-UTF-8 files are input errors.
pub fn read_text(path: &Path) -> Result<String, InputError> {
    let bytes =
        std::fs::read(path).map_err(|e| InputError::file(path, format!("cannot read the file: {e}")))?;
    String::from_utf8(bytes).map_err(|e| {
        InputError::file(
            path,
            format!("not UTF-8 text (invalid byte at offset {})", e.utf8_error().valid_up_to()),
        )
    })
}
