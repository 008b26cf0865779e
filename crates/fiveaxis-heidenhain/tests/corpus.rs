//! The HEIDENHAIN programs of the shared corpus run to their end (the
//! test says so and passes when the corpus is absent).

mod common;

use common::{FakeSystem, StrictText};
use fiveaxis_heidenhain::{Executed, Interpreter, Kind, MemoryStore, Options, Step};

const PROGRAMS: [&str; 3] = [
    "heidenhain_hypermill_dmu85_a7.h",
    "heidenhain_hypermill_dmu85_a10.h",
    "heidenhain_hypermill_dmu85_b5.h",
];

const DIR: &str = "/work/shared/corpus";

#[test]
fn corpus_programs_run_to_their_end() {
    if !std::path::Path::new(DIR).is_dir() {
        println!("SKIPPED: {DIR} is absent");
        return;
    }
    for name in PROGRAMS {
        let path = format!("{DIR}/{name}");
        let Ok(text) = std::fs::read_to_string(&path) else {
            println!("SKIPPED: {path} is absent");
            continue;
        };
        for skip in [true, false] {
            let mut i = Interpreter::new(
                Box::new(StrictText::new(&text)),
                Box::new(MemoryStore::new()),
                Options {
                    block_skip: skip,
                    max_blocks: 1_000_000,
                },
            )
            .expect("new");
            let mut sys = FakeSystem::default();
            let mut b = Executed::default();
            let mut yielded = 0u64;
            let mut lines = 0u64;
            loop {
                match i.next_block(&mut sys, &mut b) {
                    Ok(Step::Block) => {
                        yielded += 1;
                        if b.kind == Kind::Line {
                            lines += 1;
                        }
                        // PLANE … STAY: the control writes Q120–Q122.
                        if b.kind == Kind::Plane {
                            i.set_q(120, 90.0);
                            i.set_q(122, 180.0);
                        }
                    }
                    Ok(Step::End) => break,
                    Err(e) => panic!(
                        "{name} line {}: {} ({:?}) {:?}",
                        e.line,
                        e.message,
                        e.kind,
                        String::from_utf8_lossy(i.line_text())
                    ),
                }
            }
            assert!(i.program_name(0).starts_with("W5270NS01060"), "{name}");
            assert!(yielded > 20, "{name}: {yielded} blocks");
            assert!(lines > 10, "{name}: {lines} L blocks");
            println!("{name} (skip {skip}): {yielded} blocks, {} run", i.blocks());
        }
    }
}
