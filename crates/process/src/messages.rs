//! The one place brdfprof talks to the user on stderr about a run (its results go to stdout and files):
//! `brdfprof: warning: ...`, `brdfprof: note: ...`, `brdfprof: error: ...` and progress lines
//! `brdfprof: ...`, each printed whole (one `eprintln!` per message, so that lines of several threads do not
//! interleave) and, while a progress bar is drawn, around it (`ProgressGuard`), so that neither garbles the
//! other.
//!
//! Child processes (`__noop-child`, `__callgrind-child`) parse the same models as their parent, which has
//! already said what there is to say about them: in a child, `input_warning`/`input_note` print nothing.

use std::fmt::Display;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

/// Prints a line, suspending the progress bar while it does.
type Printer = Arc<dyn Fn(&str) + Send + Sync>;

static PRINTER: Mutex<Option<Printer>> = Mutex::new(None);
static CHILD: AtomicBool = AtomicBool::new(false);
static VERBOSE: AtomicBool = AtomicBool::new(false);

/// `--verbose`: every note about the user's input, each on its own line (by default alike ones are one line
/// with a count, and notes that need no action are left out).
pub fn set_verbose(on: bool) {
    VERBOSE.store(on, Ordering::SeqCst);
}

pub fn verbose() -> bool {
    VERBOSE.load(Ordering::SeqCst)
}

/// `lines` (each `FILE:LINE: message`) with those alike (the same message but for its backquoted names) said
/// once: the first, then "and N more alike" with each other's line and name; `--verbose` keeps them all.
pub fn grouped(lines: &[String]) -> Vec<String> {
    if verbose() {
        return lines.to_vec();
    }
    let shape = |l: &str| -> (String, String) {
        let (at, message) = match l.match_indices(": ").next() {
            Some((i, _)) => (l[..i].to_string(), l[i + 2..].to_string()),
            None => (String::new(), l.to_string()),
        };
        let file = at.rsplit_once(':').map_or(at.clone(), |(f, _)| f.to_string());
        let mut key = String::new();
        for (k, part) in message.split('`').enumerate() {
            key += if k % 2 == 1 { "`_`" } else { part };
        }
        (file, key)
    };
    let mut out: Vec<(String, (String, String), Vec<String>)> = Vec::new();
    for l in lines {
        let s = shape(l);
        match out.iter_mut().find(|(_, k, _)| *k == s) {
            Some((_, _, more)) => more.push(l.clone()),
            None => out.push((l.clone(), s, Vec::new())),
        }
    }
    out.into_iter()
        .map(|(first, _, more)| {
            if more.is_empty() {
                return first;
            }
            // Each other's line, and the first backquoted name in which it differs from the first.
            let quoted = |l: &str| l.split('`').skip(1).step_by(2).map(str::to_string).collect::<Vec<_>>();
            let first_names = quoted(&first);
            let named: Vec<String> = more
                .iter()
                .map(|m| {
                    let line = m.split(": ").next().and_then(|a| a.rsplit(':').next()).unwrap_or("?");
                    let names = quoted(m);
                    let name = names.iter().zip(&first_names).find(|(a, b)| a != b).map_or("", |(a, _)| a.as_str());
                    format!("line {line} `{name}`")
                })
                .collect();
            format!("{first} (and {} more alike: {}; --verbose says each)", more.len(), named.join(", "))
        })
        .collect()
}

/// Text from an input (a path, a label, shader text) as one line of our output may hold it: every control
/// character (newline, CR, escape, the C1 controls, ...) written as its Rust escape (`\n`, `\u{1b}`), so that no
/// input ends our line and starts one of its own. Other characters, non-ASCII ones included, are kept.
pub fn escape_line(text: &str) -> String {
    if !text.chars().any(char::is_control) {
        return text.to_string();
    }
    text.chars().map(|c| if c.is_control() { c.escape_debug().to_string() } else { c.to_string() }).collect()
}

/// Text as brdfprof writes it to stdout, stderr, a step summary or a Markdown file: its own line breaks (and
/// tabs) kept, every other control character escaped (`escape_line`), and no line left that GitHub's runner
/// would take for a workflow command: one that starts with `::` after its leading blanks (the runner trims
/// them) gets a backslash first (`\::`, which Markdown shows as `::`), and a legacy `##[` becomes `##\[`.
/// brdfprof's own annotations (`export::github`) are the only lines that start with `::`, and are written
/// without it. This is the last line of defence; names are escaped where they are formatted too.
pub fn safe_text(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for (i, line) in text.split('\n').enumerate() {
        if i > 0 {
            out.push('\n');
        }
        let blank = line.len() - line.trim_start().len();
        let (lead, rest) = line.split_at(blank);
        out += &lead
            .chars()
            .map(|c| if c == '\t' || !c.is_control() { c.to_string() } else { c.escape_debug().to_string() })
            .collect::<String>();
        if rest.starts_with("::") {
            out.push('\\');
        }
        for c in rest.chars() {
            if c.is_control() && c != '\t' {
                out += &c.escape_debug().to_string();
            } else {
                out.push(c);
            }
        }
    }
    out.replace("##[", "##\\[")
}

/// Prints `line` on stderr (`safe_text`: no input can start a line of its own there; every other function here
/// adds the prefix first).
pub fn line(line: &str) {
    let line = safe_text(line);
    let printer = PRINTER.lock().unwrap_or_else(|e| e.into_inner()).clone();
    match printer {
        Some(p) => p(&line),
        None => eprintln!("{line}"),
    }
}

/// `brdfprof: warning: TEXT`: something is likely wrong but the command goes on.
pub fn warning(text: impl Display) {
    line(&format!("brdfprof: warning: {text}"));
}

/// `brdfprof: note: TEXT`: what the user may want to know about how the command ran.
pub fn note(text: impl Display) {
    line(&format!("brdfprof: note: {text}"));
}

/// `brdfprof: error: TEXT`: why the command stops (the caller exits with status 2).
pub fn error(text: impl Display) {
    line(&format!("brdfprof: error: {text}"));
}

/// `brdfprof: TEXT`: what the command is doing or did (rows written, compilations under way).
pub fn progress(text: impl Display) {
    line(&format!("brdfprof: {text}"));
}

/// Whether `text` is new in this process (the first call with it answers true).
fn first_time(text: &str) -> bool {
    static SEEN: OnceLock<Mutex<std::collections::HashSet<String>>> = OnceLock::new();
    SEEN.get_or_init(Mutex::default).lock().unwrap_or_else(|e| e.into_inner()).insert(text.to_string())
}

/// `warning`, once per process for the same text.
pub fn warning_once(text: impl Display) {
    let text = text.to_string();
    if first_time(&format!("warning: {text}")) {
        warning(text);
    }
}

/// `note`, once per process for the same text.
pub fn note_once(text: impl Display) {
    let text = text.to_string();
    if first_time(&format!("note: {text}")) {
        note(text);
    }
}

/// Marks this process as a child of brdfprof: input warnings and notes were the parent's to print.
pub fn set_child_process() {
    CHILD.store(true, Ordering::SeqCst);
}

/// Whether this process is one of brdfprof's own children (`set_child_process`).
pub fn is_child_process() -> bool {
    CHILD.load(Ordering::SeqCst)
}

/// A warning about the user's input (a model file, a parameter): once per process, never in a child.
pub fn input_warning(text: impl Display) {
    if !CHILD.load(Ordering::SeqCst) {
        warning_once(text);
    }
}

/// A note about the user's input: once per process, never in a child.
pub fn input_note(text: impl Display) {
    if !CHILD.load(Ordering::SeqCst) {
        note_once(text);
    }
}

/// How often a `Heartbeat` speaks.
pub const HEARTBEAT_EVERY: std::time::Duration = std::time::Duration::from_secs(10);

/// While it lives, and only where stderr is not a terminal (a CI log, which shows no progress bar), a progress
/// line every `HEARTBEAT_EVERY` saying what `what` says and for how long, so that a long command is never silent.
pub struct Heartbeat {
    stop: Option<std::sync::mpsc::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Heartbeat {
    pub fn start(what: impl Fn() -> String + Send + 'static) -> Heartbeat {
        if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
            return Heartbeat { stop: None, thread: None };
        }
        let (stop, stopped) = std::sync::mpsc::channel::<()>();
        let started = std::time::Instant::now();
        let thread = std::thread::spawn(move || {
            while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) = stopped.recv_timeout(HEARTBEAT_EVERY) {
                progress(format!("{}, {} s", what(), started.elapsed().as_secs()));
            }
        });
        Heartbeat { stop: Some(stop), thread: Some(thread) }
    }
}

impl Drop for Heartbeat {
    fn drop(&mut self) {
        drop(self.stop.take());
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// While it lives, messages are printed through `suspend` (a progress bar's `suspend`, which hides the bar,
/// runs the print and draws the bar again).
pub struct ProgressGuard(());

impl ProgressGuard {
    pub fn new(suspend: impl Fn(&mut dyn FnMut()) + Send + Sync + 'static) -> ProgressGuard {
        let printer: Printer = Arc::new(move |text: &str| suspend(&mut || eprintln!("{text}")));
        *PRINTER.lock().unwrap_or_else(|e| e.into_inner()) = Some(printer);
        ProgressGuard(())
    }
}

impl Drop for ProgressGuard {
    fn drop(&mut self) {
        *PRINTER.lock().unwrap_or_else(|e| e.into_inner()) = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_input_starts_a_workflow_command() {
        let planted = "model x\n::stop-commands::TOKEN\r\n  ::error::forged\u{1b}[31m\n##[set-env name=X]y\tz";
        let safe = safe_text(planted);
        for line in safe.lines() {
            assert!(!line.trim_start().starts_with("::"), "{line:?}");
            assert!(!line.contains("##[") && !line.chars().any(|c| c.is_control() && c != '\t'), "{line:?}");
        }
        assert_eq!(safe.lines().count(), planted.split('\n').count(), "its own line breaks kept");
        assert!(safe.contains("\\::stop-commands::TOKEN\\r") && safe.contains("\\u{1b}[31m"), "{safe}");
        assert_eq!(safe_text("| a | b |\n\n- café"), "| a | b |\n\n- café");
        assert_eq!(escape_line("a\nb"), "a\\nb");
    }

    #[test]
    fn once_means_once_per_text() {
        assert!(first_time("messages test: a"));
        assert!(!first_time("messages test: a"));
        assert!(first_time("messages test: b"));
    }

    #[test]
    fn a_progress_guard_routes_messages_while_it_lives() {
        let seen = Arc::new(Mutex::new(0));
        let counter = seen.clone();
        let guard = ProgressGuard::new(move |print| {
            *counter.lock().unwrap() += 1;
            print();
        });
        note("messages test: through the guard");
        assert!(*seen.lock().unwrap() >= 1, "printed through the guard");
        drop(guard);
        assert!(PRINTER.lock().unwrap().is_none(), "and straight to stderr after it");
    }
}
