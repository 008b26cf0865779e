//! The interpreter runs the SINUMERIK programs of the shared corpus to
//! their end, with a fake control that reads every `$` variable as 0 and
//! carries out every cycle, and stubs of the programs they call.

mod common;

use common::fake::{FakeStore, FakeSystem, run_with};
use fiveaxis_sinumerik::Options;

/// Each program, whether it is a big one (more than 100 blocks), and the
/// program it stands for in the store when called.
const PROGRAMS: [(&str, bool); 8] = [
    ("siemens_bladmill_starrag_main.mpf", true),
    ("siemens_bladmill_starrag_traori.spf", true),
    ("siemens_nx_ftv5_840d.mpf", true),
    ("siemens_pyronc_atsumu.mpf", true),
    ("siemens_pyronc_strojnica.mpf", true),
    ("siemens_spinner_u5_achskreuz.mpf", true),
    ("siemens_spinner_u5_bottle_opener.mpf", true),
    ("siemens_spinner_u5_keychain.mpf", true),
];

/// The names a program calls with `EXTCALL("…")`.
fn extcalls(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in text.lines() {
        if line.trim_start().starts_with(';') {
            continue;
        }
        let upper = line.to_ascii_uppercase();
        if let Some(at) = upper.find("EXTCALL(\"") {
            let rest = &upper[at + 9..];
            if let Some(end) = rest.find('"') {
                out.push(rest[..end].to_string());
            }
        }
    }
    out
}

#[test]
fn corpus_programs_run_to_their_end() {
    let Some(traori) = common::corpus::corpus_path("siemens_bladmill_starrag_traori.spf") else {
        return;
    };
    let traori = std::fs::read_to_string(traori).expect("read the subprogram");
    let mut failures = Vec::new();
    for (name, big) in PROGRAMS {
        let Some(path) = common::corpus::corpus_path(name) else {
            return;
        };
        let text = String::from_utf8_lossy(&std::fs::read(&path).expect("read")).into_owned();
        let mut store = FakeStore::with(&[
            ("RLIMIT", "; OEM cycle stub\nM17\n"),
            (
                "RAPORT",
                "PROC RAPORT(STRING[40] A, STRING[80] B)\n; report stub\nRET\n",
            ),
            ("4444411", &traori),
        ])
        .define("GUD", "DEF NCK INT E_ZDARZ\n");
        for called in extcalls(&text) {
            store
                .programs
                .entry(called.clone())
                .or_insert_with(|| format!("; stub of {called}\nG0 X0\nM17\n"));
        }
        let mut sys = FakeSystem {
            zero_reads: true,
            all_builtin: true,
            ..FakeSystem::default()
        };
        let r = run_with(&text, store, &mut sys, Options::default());
        let blocks = r.blocks.len();
        println!(
            "{name}: {blocks} blocks, {} lines read, {} notes",
            r.lines,
            r.notes.len()
        );
        if let Some(e) = &r.error {
            failures.push(format!("{name}: {} line {}: {e:?}", e.program, e.line));
            continue;
        }
        if big && blocks <= 100 {
            failures.push(format!("{name}: only {blocks} blocks"));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
