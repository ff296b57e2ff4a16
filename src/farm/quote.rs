//! The one way a value enters a farm script: [`shell_word`] makes any text one word of a POSIX
//! shell command line, whatever it holds (quotes, `$( )`, backticks, newlines, `---`, globs),
//! and [`comment`] makes it safe inside a `#` comment. Everything [`super::slurm`] and
//! [`super::kubernetes`] write that came from the user goes through one of the two (the
//! manifest's YAML itself comes from a serializer).
//!
//! Single quotes are the shell's only quoting in which no character is special (POSIX.1-2017,
//! *Shell Command Language* §2.2.2): a value is wrapped in them, and each `'` in it is closed,
//! written as `\'` and reopened. A newline inside single quotes is a literal newline, so the
//! scripts never put a quoted word where a line ends something — a heredoc, a `#SBATCH`
//! directive, a comment.

use std::ffi::OsStr;

/// A value no shell word can carry.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum QuoteError {
    /// Bytes that are not UTF-8 (a YAML manifest cannot hold them, and a script that held
    /// them would be unreadable to most editors and terminals).
    #[error("{0:?} is not valid UTF-8: a batch script or manifest cannot name it; rename it")]
    NotUtf8(String),
    /// A NUL byte, which no command-line argument can hold.
    #[error("{0:?} holds a NUL character, which no command-line argument can hold")]
    Nul(String),
}

/// Characters that need no quoting in any POSIX shell, in any position of a word.
fn plain(c: char) -> bool {
    c.is_ascii_alphanumeric() || "/._-=:,+@%".contains(c)
}

/// `value` as one word of a POSIX shell (bash, dash, sh -c): itself when it holds only
/// characters no shell treats specially, else in single quotes. The shell reads the word back
/// as exactly `value`.
pub fn shell_word(value: &OsStr) -> Result<String, QuoteError> {
    let Some(text) = value.to_str() else {
        return Err(QuoteError::NotUtf8(value.to_string_lossy().into_owned()));
    };
    if text.contains('\0') {
        return Err(QuoteError::Nul(text.to_owned()));
    }
    if !text.is_empty() && text.chars().all(plain) {
        return Ok(text.to_owned());
    }
    Ok(format!("'{}'", text.replace('\'', r"'\''")))
}

/// [`shell_word`] of text known to be UTF-8 without NUL (the program's own words and numbers
/// joined with user values already checked); a NUL is dropped rather than panicking.
pub fn shell_text(text: &str) -> String {
    shell_word(OsStr::new(&text.replace('\0', ""))).unwrap_or_default()
}

/// `value` for a `#` comment line: in double quotes with every line break, control character
/// and non-printing character escaped (Rust's `{:?}`), so the comment ends where the line does.
pub fn comment(value: &OsStr) -> String {
    match value.to_str() {
        Some(text) => format!("{text:?}"),
        None => format!("{value:?}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_words_stay_as_they_are() {
        for w in [
            "cornell.toml",
            "/data/out/part_1.exr",
            "--width=1920",
            "a,b:c@d%e+f",
        ] {
            assert_eq!(shell_word(OsStr::new(w)).as_deref(), Ok(w));
        }
    }

    #[test]
    fn everything_else_is_single_quoted() {
        let cases = [
            ("", "''"),
            ("a b", "'a b'"),
            ("it's", r"'it'\''s'"),
            ("$(touch x)", "'$(touch x)'"),
            ("a\nb", "'a\nb'"),
            ("*", "'*'"),
            ("~", "'~'"),
        ];
        for (value, quoted) in cases {
            assert_eq!(shell_word(OsStr::new(value)).as_deref(), Ok(quoted), "{value:?}");
        }
    }

    #[cfg(unix)]
    #[test]
    fn non_utf8_and_nul_are_refused() {
        use std::os::unix::ffi::OsStrExt;
        let bytes = OsStr::from_bytes(b"out\xff");
        assert!(matches!(shell_word(bytes), Err(QuoteError::NotUtf8(_))));
        assert!(matches!(shell_word(OsStr::new("a\0b")), Err(QuoteError::Nul(_))));
        assert!(!comment(bytes).contains('\n'));
    }

    #[test]
    fn comments_hold_no_line_break() {
        for v in [
            "a\nb",
            "a\rb",
            "a\u{2028}b",
            "a\u{85}b",
            "a\u{2029}b",
            "a\u{b}b",
            "a\u{c}b",
        ] {
            let c = comment(OsStr::new(v));
            assert!(
                !c.contains(['\n', '\r', '\u{2028}', '\u{2029}', '\u{85}', '\u{b}', '\u{c}']),
                "{c}"
            );
        }
    }
}
