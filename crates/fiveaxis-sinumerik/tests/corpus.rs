//! Every line of the SINUMERIK programs of the shared corpus reads
//! without an error.

mod common;

use std::collections::BTreeMap;

use fiveaxis_sinumerik::{CallKind, Item, Statement, parse_line};

const PROGRAMS: [&str; 8] = [
    "siemens_bladmill_starrag_main.mpf",
    "siemens_bladmill_starrag_traori.spf",
    "siemens_nx_ftv5_840d.mpf",
    "siemens_pyronc_atsumu.mpf",
    "siemens_pyronc_strojnica.mpf",
    "siemens_spinner_u5_achskreuz.mpf",
    "siemens_spinner_u5_bottle_opener.mpf",
    "siemens_spinner_u5_keychain.mpf",
];

/// The kinds of statement and item of a line, for the tally.
fn kinds(statement: &Statement, tally: &mut BTreeMap<String, usize>) {
    let kind = match statement {
        Statement::Block(items) => {
            for item in items {
                let kind = match item {
                    Item::Word(w) => format!("word {}", w.address),
                    Item::Assign(_) => "assign".to_string(),
                    Item::Call(c) if c.kind == CallKind::User => "call (user)".to_string(),
                    Item::Call(c) => format!("call {}", c.name),
                    Item::ModalCall { .. } => "MCALL".to_string(),
                    Item::IndirectCall(_) => "CALL".to_string(),
                    Item::Jump(j) => format!("{:?}", j.kind),
                };
                *tally.entry(kind).or_default() += 1;
            }
            return;
        }
        other => {
            let debug = format!("{other:?}");
            debug
                .split(['(', ' ', '{'])
                .next()
                .unwrap_or_default()
                .to_string()
        }
    };
    *tally.entry(kind).or_default() += 1;
}

#[test]
fn every_siemens_program_of_the_corpus_reads() {
    let mut errors = Vec::new();
    for name in PROGRAMS {
        let Some(path) = common::corpus::corpus_path(name) else {
            return;
        };
        let bytes = std::fs::read(&path).expect("read the program");
        let mut tally = BTreeMap::new();
        let mut lines = 0;
        let mut failed = 0;
        for (i, text) in bytes.split(|&b| b == b'\n').enumerate() {
            if i + 1 == bytes.split(|&b| b == b'\n').count() && text.is_empty() {
                break;
            }
            lines += 1;
            let number = u32::try_from(i + 1).expect("line number");
            match parse_line(text, number) {
                Ok(line) => {
                    if line.label.is_some() {
                        *tally.entry("label".to_string()).or_default() += 1;
                    }
                    kinds(&line.statement, &mut tally);
                }
                Err(e) => {
                    failed += 1;
                    errors.push(format!("{name}:{e} in `{}`", String::from_utf8_lossy(text)));
                }
            }
        }
        println!("{name}: {lines} lines, {failed} errors");
        for (kind, count) in &tally {
            println!("    {kind}: {count}");
        }
    }
    assert!(errors.is_empty(), "{}", errors.join("\n"));
}
