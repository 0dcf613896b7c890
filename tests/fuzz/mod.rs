//! A seeded fuzzer of the `restitution` binary, shared by `tests/fuzz_cli.rs` (a small seeded
//! subset, part of `cargo test`) and `examples/fuzz_cli.rs` (as many cases as asked).
//!
//! Each case is a command line and the files it reads, made from valid data by a few mutations
//! (extreme magnitudes, zeros, negative values, NaN/inf text, huge and tiny error bars, duplicated
//! rows, one row, 100 000 rows, bytes that are not UTF-8, quotes and commas in ids, broken CSV
//! structure) or from flags with extreme values. The binary runs as a subprocess with a time
//! limit (2 s of CPU, see [`Runner`]); a case passes when the process ends in time and either
//! succeeds with no NaN or
//! infinity printed where a number belongs (stdout and every output file; a JSON document's
//! `skipped` lines, like the warnings, may name the value a collision overflowed to), or fails with one
//! error line (plus warnings) that names the file or the flag, a non-zero exit, and no output
//! file left behind. A panic, a signal or a timeout fails the case.

#![allow(dead_code)]

pub mod cases;
pub mod sheet;

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// One command line with the files it reads. In `args`, `{dir}` stands for the case's directory.
#[derive(Debug, Clone)]
pub struct Case {
    pub label: String,
    pub args: Vec<String>,
    pub files: Vec<(String, Vec<u8>)>,
    /// Whether the command writes into `{dir}/out` (checked for NaN, and for emptiness on failure).
    pub out_dir: bool,
}

/// What a run gave.
#[derive(Debug)]
pub struct Outcome {
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
    pub elapsed: Duration,
    /// CPU time (user + system) last seen while the process ran (Linux; zero elsewhere).
    pub cpu: Duration,
    pub timed_out: bool,
}

/// Runs cases of one binary, each in its own directory under `root`.
///
/// A case may use `limit` of CPU time (2 s). The limit is on CPU rather than wall time because
/// the machines are shared: with a load of 12 on 2 cores, a 0.5 s job takes 2 s of wall time,
/// while a hang burns CPU however busy the machine is. `wall_limit` (20 s) catches a process
/// that hangs without using CPU.
pub struct Runner {
    pub bin: PathBuf,
    pub root: PathBuf,
    pub limit: Duration,
    pub wall_limit: Duration,
}

/// User + system CPU time of a running process, from /proc/PID/stat (fields 14 and 15, in
/// clock ticks of 1/100 s, Linux's USER_HZ). `None` where there is no /proc.
fn cpu_time(pid: u32) -> Option<Duration> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) is in parentheses and may contain spaces: count after it.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: u64 = f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?;
    Some(Duration::from_millis(ticks * 10))
}

fn drain(mut r: impl Read + Send + 'static) -> std::thread::JoinHandle<Vec<u8>> {
    std::thread::spawn(move || {
        let mut v = Vec::new();
        let _ = r.read_to_end(&mut v);
        v
    })
}

impl Runner {
    pub fn new(bin: PathBuf, tag: &str) -> Runner {
        let root =
            std::env::temp_dir().join(format!("restitution-fuzz-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(&root).expect("a temporary directory");
        Runner {
            bin,
            root,
            limit: Duration::from_secs(2),
            wall_limit: Duration::from_secs(20),
        }
    }

    pub fn case_dir(&self, index: usize) -> PathBuf {
        self.root.join(format!("c{index}"))
    }

    /// Runs `case` (files written first); the process is killed at the time limit.
    pub fn run(&self, case: &Case, index: usize) -> Outcome {
        let dir = self.case_dir(index);
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("a case directory");
        for (name, bytes) in &case.files {
            let path = dir.join(name);
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).expect("a case file's directory");
            }
            std::fs::write(path, bytes).expect("writing a case file");
        }
        let d = dir.display().to_string();
        let args: Vec<String> = case.args.iter().map(|a| a.replace("{dir}", &d)).collect();
        let start = Instant::now();
        let mut child = Command::new(&self.bin)
            .args(&args)
            .current_dir(&dir)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the binary starts");
        let out = drain(child.stdout.take().expect("piped"));
        let err = drain(child.stderr.take().expect("piped"));
        let mut timed_out = false;
        let mut cpu = Duration::ZERO;
        let status = loop {
            match child.try_wait().expect("waiting for the child") {
                Some(s) => break s,
                None => {
                    cpu = cpu_time(child.id()).unwrap_or(cpu);
                    if cpu > self.limit || start.elapsed() > self.wall_limit {
                        timed_out = true;
                        let _ = child.kill();
                        break child.wait().expect("reaping the killed child");
                    }
                    std::thread::sleep(Duration::from_millis(2));
                }
            }
        };
        let elapsed = start.elapsed();
        let stdout = String::from_utf8_lossy(&out.join().unwrap_or_default()).into_owned();
        let stderr = String::from_utf8_lossy(&err.join().unwrap_or_default()).into_owned();
        Outcome {
            code: status.code(),
            stdout,
            stderr,
            elapsed,
            cpu,
            timed_out,
        }
    }

    /// Runs and judges a case. `Err` says what was wrong.
    pub fn check(&self, case: &Case, index: usize) -> Result<Outcome, String> {
        let o = self.run(case, index);
        judge(case, &o, &self.case_dir(index))?;
        Ok(o)
    }
}

/// Words that mean a number is not finite, except those that are ids of the input (an id may
/// be any text, `inf` included).
fn non_finite_word_except(text: &str, ids: &[String]) -> Option<String> {
    text.split(|c: char| !c.is_ascii_alphanumeric())
        .find(|w| {
            let l = w.to_ascii_lowercase();
            (l == "nan" || l == "inf" || l == "infinity") && !ids.iter().any(|id| id.contains(*w))
        })
        .map(|w| {
            let at = text.find(w).unwrap_or(0);
            let from = text[..at].rfind('\n').map_or(0, |p| p + 1);
            let to = text[at..].find('\n').map_or(text.len(), |p| at + p);
            format!("'{w}' in: {}", &text[from..to.min(from + 200)])
        })
}

fn non_finite_word(text: &str) -> Option<String> {
    non_finite_word_except(text, &[])
}

/// A CSV text with the `inf` cells of its `d2_mm` column blanked: in every schema of the
/// toolkit (fit data, export tables) `d2_mm = inf` is a flat wall, the one place where `inf` is
/// the right value. Every other cell is kept (comment lines too), so any other non-finite word
/// is still found.
fn without_wall_diameters(text: &str) -> String {
    let mut out = String::new();
    let mut column: Option<usize> = None;
    for line in text.lines() {
        if line.starts_with('#') || line.is_empty() {
            out += line;
            out.push('\n');
            continue;
        }
        let cells: Vec<&str> = line.split(',').collect();
        match column {
            None => {
                column = Some(
                    cells
                        .iter()
                        .position(|c| *c == "d2_mm")
                        .unwrap_or(usize::MAX),
                )
            }
            Some(k) => {
                let kept: Vec<&str> = cells
                    .iter()
                    .enumerate()
                    .map(|(i, c)| if i == k && *c == "inf" { "" } else { *c })
                    .collect();
                out += &kept.join(",");
                out.push('\n');
                continue;
            }
        }
        out += line;
        out.push('\n');
    }
    out
}

/// A JSON document without its `skipped` list: lines that name, like the warnings on stderr, the
/// input a collision could not be measured from, and the value that overflowed
/// ("e_err_eq8 = -inf (the tracks or flags are out of range)"). Any other text is kept as it is.
fn without_skip_messages(text: &str) -> String {
    match serde_json::from_str::<serde_json::Value>(text) {
        Ok(serde_json::Value::Object(mut doc)) if doc.contains_key("skipped") => {
            doc.remove("skipped");
            serde_json::to_string_pretty(&doc).expect("a parsed document serialises")
        }
        _ => text.to_string(),
    }
}

/// The values of the id columns (`collision`, `id`) of the case's input files.
fn input_ids(case: &Case) -> Vec<String> {
    let mut ids = Vec::new();
    for (name, bytes) in &case.files {
        if let Ok(t) = restitution::data::Table::parse_bytes(name, bytes) {
            for col in ["collision", "id"] {
                if let Some(c) = t.column(col) {
                    ids.extend(t.rows.iter().map(|r| t.field(r, c).to_string()));
                }
            }
        }
    }
    ids.retain(|id| {
        let l = id.to_ascii_lowercase();
        l.contains("nan") || l.contains("inf")
    });
    ids
}

fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    if let Ok(rd) = std::fs::read_dir(dir) {
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                out.extend(files_under(&p));
            } else {
                out.push(p);
            }
        }
    }
    out
}

/// The rules every case must keep (see the module doc).
pub fn judge(case: &Case, o: &Outcome, dir: &Path) -> Result<(), String> {
    if o.timed_out {
        return Err(format!(
            "hang: killed after {:.1} s of CPU, {:.1} s of wall time",
            o.cpu.as_secs_f64(),
            o.elapsed.as_secs_f64()
        ));
    }
    if o.stderr.contains("panicked") || o.code == Some(101) {
        return Err(format!("panic: {}", o.stderr.trim()));
    }
    let Some(code) = o.code else {
        return Err("killed by a signal".into());
    };
    let out_dir = dir.join("out");
    if code == 0 {
        let ids = input_ids(case);
        if let Some(w) = non_finite_word_except(&without_skip_messages(&o.stdout), &ids) {
            return Err(format!("non-finite number on stdout: {w}"));
        }
        if case.out_dir {
            for f in files_under(&out_dir) {
                let mut text =
                    String::from_utf8_lossy(&std::fs::read(&f).unwrap_or_default()).into_owned();
                if f.extension().is_some_and(|e| e == "csv") {
                    text = without_wall_diameters(&text);
                }
                if f.extension().is_some_and(|e| e == "json") {
                    // The JSON form of the same convention (export.json's pairs).
                    text = text.replace("\"d2_mm\": \"inf\"", "\"d2_mm\": \"wall\"");
                }
                if let Some(w) = non_finite_word_except(&text, &ids) {
                    return Err(format!("non-finite number in {}: {w}", f.display()));
                }
            }
        }
        return Ok(());
    }
    let lines: Vec<&str> = o
        .stderr
        .lines()
        .filter(|l| !l.starts_with("restitution: warning: "))
        .collect();
    if lines.len() != 1 || !lines[0].starts_with("restitution: error: ") {
        return Err(format!(
            "exit {code} without one error line: {:?}",
            o.stderr
        ));
    }
    let line = lines[0];
    // A file, or the directory holding it (`track` names a directory without frames).
    let names_file = case.files.iter().any(|(n, _)| {
        line.contains(n.as_str())
            || Path::new(n)
                .parent()
                .and_then(|p| p.to_str())
                .is_some_and(|p| !p.is_empty() && line.contains(&format!("{p}:")))
    });
    let names_flag = line.contains("--") || line.contains("(see --help)");
    if !(names_file || names_flag) {
        return Err(format!("the error names neither a file nor a flag: {line}"));
    }
    if let Some(w) = non_finite_word(&o.stdout) {
        return Err(format!("non-finite number on stdout of a failed run: {w}"));
    }
    if case.out_dir {
        let left = files_under(&out_dir);
        if !left.is_empty() {
            return Err(format!("failed, but left output files: {left:?}"));
        }
    }
    Ok(())
}

/// The binary next to the running program (`target/<profile>/restitution` for an example in
/// `target/<profile>/examples/`).
pub fn sibling_binary() -> PathBuf {
    let exe = std::env::current_exe().expect("the running program's path");
    let dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("target/<profile>");
    dir.join(format!("restitution{}", std::env::consts::EXE_SUFFIX))
}

/// Summary of a batch: (cases, successes, clean errors, failures with their descriptions).
#[derive(Debug, Default)]
pub struct Tally {
    pub cases: usize,
    pub ok: usize,
    pub errors: usize,
    pub slowest: (f64, String),
    pub failures: Vec<String>,
}

impl Tally {
    pub fn add(&mut self, case: &Case, result: Result<Outcome, String>) {
        self.cases += 1;
        match result {
            Ok(o) => {
                if o.code == Some(0) {
                    self.ok += 1;
                } else {
                    self.errors += 1;
                }
                let t = o.elapsed.as_secs_f64();
                if t > self.slowest.0 {
                    self.slowest = (t, case.label.clone());
                }
            }
            Err(why) => self.failures.push(format!(
                "{}\n    restitution {}\n    files: {}\n    {why}",
                case.label,
                case.args.join(" "),
                case.files
                    .iter()
                    .map(|(n, b)| format!("{n} ({} bytes)", b.len()))
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        }
    }
}
