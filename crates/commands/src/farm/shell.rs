//! The one way a farm writes a word into a shell script (`tasks.sbatch`,
//! `merge.sbatch`, `submit.sh`, `submit-k8s.sh`) or into a command it
//! tells the user to run: job folders are shared on farms, and their
//! names come from whoever made them.

/// `word` as one word of a POSIX shell: inside single quotes, where
/// nothing is special but the single quote itself, written `'\''` (close,
/// an escaped quote, open again). The result is a whole word: it is never
/// placed inside a double-quoted string, where its single quotes would be
/// literal and a `"` in `word` would end the string (issue 47).
pub fn quoted(word: &str) -> String {
    format!("'{}'", word.replace('\'', r"'\''"))
}

/// A line a script prints to stderr, `message` written by `printf '%s\n'`
/// as one quoted word: no expansion, no backslash escape (which `echo`
/// interprets in some shells), whatever the message holds.
pub fn error_line(message: &str) -> String {
    format!("printf '%s\\n' {} >&2", quoted(message))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shell reads each quoted word back as it was, and runs none of
    /// it; a message holding quoted words prints them as written.
    #[test]
    fn bash_reads_every_quoted_word_back_as_written() {
        let dir = tempfile::tempdir().unwrap();
        let words = [
            "plain",
            "it's",
            "kq\";touch${IFS}PLANTED;\"",
            "s'$(touch PLANTED)'",
            "b`touch PLANTED`",
            "-n",
            "a\\nb \\ c",
            "'",
            "",
        ];
        let script: String = words
            .iter()
            .map(|w| format!("printf '%s\\0' {}\n", quoted(w)))
            .chain([error_line(&format!("run {} again", quoted(words[2])))])
            .collect();
        let out = std::process::Command::new("bash")
            .args(["-c", &script])
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(out.status.success(), "{out:?}");
        let expected: String = words.iter().map(|w| format!("{w}\0")).collect();
        assert_eq!(String::from_utf8(out.stdout).unwrap(), expected);
        assert_eq!(
            String::from_utf8(out.stderr).unwrap(),
            "run 'kq\";touch${IFS}PLANTED;\"' again\n"
        );
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
