//! Block kinds, words, keys and M functions as they reach the control.

mod common;

use common::{keys, run, w};
use fiveaxis_heidenhain::{Kind, Span, Tool};

fn one(text: &str) -> fiveaxis_heidenhain::Executed {
    let mut v = run(text);
    assert_eq!(v.len(), 1, "{text}: {v:?}");
    v.remove(0)
}

#[test]
fn straight_line_words_keys_and_m() {
    let b = one("7 L X+10 IY-5.5 Z0 R0 FMAX M3 M8");
    assert_eq!(b.kind, Kind::Line);
    assert_eq!(b.block_number, Some(7));
    assert_eq!(b.line, 1);
    assert_eq!(w(&b, "X"), 10.0);
    let y = b.word("Y").expect("Y");
    assert!(y.incremental);
    assert_eq!(y.value, -5.5);
    assert_eq!(w(&b, "Z"), 0.0);
    assert_eq!(keys(&b), ["R0", "FMAX"]);
    assert_eq!(b.m.iter().map(|m| m.0).collect::<Vec<_>>(), [3, 8]);
    assert_eq!(b.word("X").expect("X").span, Span::new(5, 9));
    assert_eq!(b.m[0].1, Span::new(28, 30));
}

#[test]
fn feeds_written_every_way() {
    let v = run(
        "Q3 = 250\nL X+1 F MAX\nL X+2 FMAX\nL X+3 F AUTO\nL X+4 FQ3\nL X+5 F+Q3\nL X+6 F200\nL X-Q3 RL\nL X+Q3 RR",
    );
    assert_eq!(keys(&v[0]), ["FMAX"]);
    assert_eq!(keys(&v[1]), ["FMAX"]);
    assert_eq!(keys(&v[2]), ["FAUTO"]);
    assert_eq!(w(&v[3], "F"), 250.0);
    assert_eq!(w(&v[4], "F"), 250.0);
    assert_eq!(w(&v[5], "F"), 200.0);
    assert_eq!(w(&v[6], "X"), -250.0);
    assert_eq!(keys(&v[6]), ["RL"]);
    assert_eq!(keys(&v[7]), ["RR"]);
}

#[test]
fn circles_and_polar_paths() {
    let v = run(
        "CC X+25 Y+25\nC X+45 Y+25 DR+\nCR X+10 Y+5 R+20 DR-\nCT X+1 Y+2\nLP PR+30 PA+60 R0\nCP IPA+90 IZ-2 DR+ F100\nCTP PR+5 PA+10\nRND R5\nCHF 2\nCC",
    );
    let kinds: Vec<_> = v.iter().map(|b| b.kind.clone()).collect();
    assert_eq!(
        kinds,
        [
            Kind::Centre,
            Kind::Circle,
            Kind::CircleRadius,
            Kind::CircleTangent,
            Kind::LinePolar,
            Kind::CirclePolar,
            Kind::CircleTangentPolar,
            Kind::Rounding,
            Kind::Chamfer,
            Kind::Centre
        ]
    );
    assert_eq!(keys(&v[1]), ["DR+"]);
    assert_eq!(w(&v[2], "R"), 20.0);
    assert_eq!(keys(&v[2]), ["DR-"]);
    assert_eq!(w(&v[4], "PR"), 30.0);
    assert_eq!(keys(&v[4]), ["R0"]);
    let pa = v[5].word("PA").expect("PA");
    assert!(pa.incremental && pa.value == 90.0);
    assert!(v[5].word("Z").expect("Z").incremental);
    assert_eq!(w(&v[7], "R"), 5.0);
    assert_eq!(w(&v[8], "CHF"), 2.0);
    assert!(v[9].words.is_empty());
}

#[test]
fn line_with_normal_vector() {
    let b = one("LN X+1 Y+2 Z+3 NX+0 NY+0.6 NZ+0.8 TX+0 TY-1 TZ+0 F1000 M128");
    assert_eq!(b.kind, Kind::LineNormal);
    assert_eq!(w(&b, "NY"), 0.6);
    assert_eq!(w(&b, "TY"), -1.0);
    assert_eq!(b.m[0].0, 128);
}

#[test]
fn approach_and_depart() {
    let v =
        run("APPR LT X+40 Y+10 LEN15 RR F100\nDEP LT LEN 12.5 F100\nAPPR CT X+1 Y+2 CCA90 R+5 RL");
    assert_eq!(v[0].kind, Kind::Approach);
    assert_eq!(v[0].name.as_deref(), Some("LT"));
    assert_eq!(w(&v[0], "LEN"), 15.0);
    assert_eq!(keys(&v[0]), ["RR"]);
    assert_eq!(v[1].kind, Kind::Depart);
    assert_eq!(w(&v[1], "LEN"), 12.5);
    assert_eq!(w(&v[2], "CCA"), 90.0);
    assert_eq!(w(&v[2], "R"), 5.0);
}

#[test]
fn tool_call_and_tool_def() {
    let v = run(
        "TOOL CALL 5 Z S3000 F200 DL+0.1 DR-0.1 DR2+0\nTOOL CALL \"MF09000001590361\" Z S566 DL+0 DR+0\nQ10 = 7\nTOOL CALL Q10 Y\nTOOL DEF 0\nTOOL DEF \"x\"\nQS1 = \"MILL\"\nTOOL CALL QS1 Z\nTOOL CALL Z S2000",
    );
    assert_eq!(v[0].kind, Kind::ToolCall);
    assert_eq!(v[0].tool, Some(Tool::Number(5)));
    assert_eq!(v[0].name.as_deref(), Some("Z"));
    assert_eq!(w(&v[0], "S"), 3000.0);
    assert_eq!(w(&v[0], "DR"), -0.1);
    assert_eq!(w(&v[0], "DR2"), 0.0);
    assert!(v[0].keys.is_empty());
    assert_eq!(v[1].tool, Some(Tool::Name("MF09000001590361".into())));
    assert_eq!(w(&v[1], "DR"), 0.0);
    assert_eq!(v[2].tool, Some(Tool::Number(7)));
    assert_eq!(v[2].name.as_deref(), Some("Y"));
    assert_eq!(v[3].kind, Kind::ToolDef);
    assert_eq!(v[3].tool, Some(Tool::Number(0)));
    assert_eq!(v[4].tool, Some(Tool::Name("x".into())));
    assert_eq!(v[5].tool, Some(Tool::Name("MILL".into())));
    assert_eq!(v[6].tool, None);
    assert_eq!(v[6].name.as_deref(), Some("Z"));
}

#[test]
fn blank_form() {
    let v = run("BLK FORM 0.1 Z X-187 Y-55.5 Z-50.6\nBLK FORM 0.2 X187 Y55.5 Z0.6");
    assert_eq!(v[0].kind, Kind::BlockForm);
    assert_eq!(v[0].number, Some(0.1));
    assert_eq!(v[0].name.as_deref(), Some("Z"));
    assert_eq!(w(&v[0], "Z"), -50.6);
    assert_eq!(v[1].number, Some(0.2));
    assert_eq!(v[1].name, None);
    assert_eq!(w(&v[1], "X"), 187.0);
}

#[test]
fn transform_cycles() {
    let v = run(
        "CYCL DEF 7.0 DATUM SHIFT\nCYCL DEF 7.1 X+10\nCYCL DEF 10.1 ROT+30\nCYCL DEF 11.1 SCL 0.5\nCYCL DEF 8.1 X Y\nCYCL DEF 32.1 T0.075\nCYCL DEF 32.2 HSC-MODE:1\nCYCL DEF 32.1\nCYCL DEF 19.0 WORKING PLANE\nCYCL DEF 19.1 A+10 B+0 C+0 F1000",
    );
    assert!(v.iter().all(|b| b.kind == Kind::CycleDef));
    assert_eq!(v[0].number, Some(7.0));
    assert_eq!(v[0].name.as_deref(), Some("DATUM SHIFT"));
    assert_eq!(v[1].number, Some(7.1));
    assert_eq!(w(&v[1], "X"), 10.0);
    assert_eq!(w(&v[2], "ROT"), 30.0);
    assert_eq!(w(&v[3], "SCL"), 0.5);
    assert_eq!(keys(&v[4]), ["X", "Y"]);
    assert_eq!(w(&v[5], "T"), 0.075);
    assert_eq!(w(&v[6], "HSC-MODE"), 1.0);
    assert!(v[7].words.is_empty() && v[7].keys.is_empty());
    assert_eq!(v[8].name.as_deref(), Some("WORKING PLANE"));
    assert_eq!(w(&v[9], "F"), 1000.0);
}

#[test]
fn machining_cycle_with_continuation_lines() {
    let text = "Q2 = 150\n61 CYCL DEF 207 RIGID TAPPING NEW~ ;first\n   Q200=3 ;SET-UP CLEARANCE~\n   Q201=-12.0296 ;DEPTH~\n   Q239=+1 ;THREAD PITCH~\n   Q206=Q2 ;FEED~\n   Q204=70 ;2ND SET-UP CLEARANCE\n62 L X159 Y7 R0 F MAX M99\n";
    let v = run(text);
    assert_eq!(v.len(), 2);
    let c = &v[0];
    assert_eq!(c.kind, Kind::CycleDef);
    assert_eq!(c.number, Some(207.0));
    assert_eq!(c.name.as_deref(), Some("RIGID TAPPING NEW"));
    assert_eq!(
        c.params,
        [
            (200, 3.0),
            (201, -12.0296),
            (239, 1.0),
            (206, 150.0),
            (204, 70.0)
        ]
    );
    assert_eq!(c.comment.as_deref(), Some("first"));
    assert_eq!(c.line, 2);
    assert_eq!(v[1].line, 8);
    assert_eq!(v[1].m[0].0, 99);
}

#[test]
fn cycle_with_name_and_continuation_marker_alone() {
    let v = run(
        "CYCL DEF 247 DATUM SETTING ~\n  Q339=+1 ;DATUM NUMBER\nCYCL DEF 392 ATC~\n   Q240=0 ;TUNING MODE~\n   Q241=1 ;WEIGHT MODE",
    );
    assert_eq!(v[0].name.as_deref(), Some("DATUM SETTING"));
    assert_eq!(v[0].param(339), Some(1.0));
    assert_eq!(v[1].name.as_deref(), Some("ATC"));
    assert_eq!(v[1].params, [(240, 0.0), (241, 1.0)]);
}

#[test]
fn cycle_call_and_pattern() {
    let v = run(
        "CYCL CALL\nCYCL CALL PAT F5000 M13\nPATTERN DEF ~\n POS1 (X+25 Y+33.5 Z+0) ~\n POS2 (X+15 IY+6.5 Z+0)",
    );
    assert_eq!(v[0].kind, Kind::CycleCall);
    assert_eq!(keys(&v[1]), ["PAT"]);
    assert_eq!(w(&v[1], "F"), 5000.0);
    assert_eq!(v[1].m[0].0, 13);
    assert_eq!(v[2].kind, Kind::PatternDef);
    assert_eq!(v[2].pattern.len(), 2);
    assert_eq!(v[2].pattern[0].kind, "POS");
    assert_eq!(v[2].pattern[0].words[1].value, 33.5);
    assert!(v[2].pattern[1].words[1].incremental);
}

#[test]
fn planes() {
    let v = run(
        "PLANE SPATIAL SPA+90 SPB+0 SPC+180 STAY SEQ- TABLE ROT\nPLANE RESET STAY\nPLANE VECTOR BX+1 BY+0 BZ+0 NX+0 NY+0 NZ+1 MOVE DIST50 F1000\nPLANE VECTOR BX+1 BY+0 BZ+0 NX+0 NY+0 NZ+1 MOVE MB50 FMAX\nPLANE AXIAL A+30 C+0 TURN MB MAX FMAX\nPLANE RELATIV SPB+20 MOVE F500\nPLANE POINTS P1X+0 P1Y+0 P1Z+0 P2X+1 P2Y+0 P2Z+0 P3X+0 P3Y+1 P3Z+0 STAY\nPLANE EULER EULPR+10 EULNU+20 EULROT+30 STAY\nPLANE PROJECTED PROPR+10 PROMIN+20 ROT+30 STAY SEQ+ COORD ROT",
    );
    assert!(v.iter().all(|b| b.kind == Kind::Plane));
    assert_eq!(v[0].name.as_deref(), Some("SPATIAL"));
    assert_eq!(w(&v[0], "SPC"), 180.0);
    assert_eq!(keys(&v[0]), ["STAY", "SEQ-", "TABLE ROT"]);
    assert_eq!(v[1].name.as_deref(), Some("RESET"));
    assert_eq!(keys(&v[1]), ["STAY"]);
    assert_eq!(w(&v[2], "DIST"), 50.0);
    assert_eq!(keys(&v[2]), ["MOVE"]);
    assert_eq!(w(&v[3], "MB"), 50.0);
    assert_eq!(keys(&v[3]), ["MOVE", "FMAX"]);
    assert_eq!(keys(&v[4]), ["TURN", "MB MAX", "FMAX"]);
    assert_eq!(w(&v[4], "A"), 30.0);
    assert_eq!(w(&v[5], "SPB"), 20.0);
    assert_eq!(w(&v[6], "P3Y"), 1.0);
    assert_eq!(w(&v[6], "P2X"), 1.0);
    assert_eq!(w(&v[7], "EULROT"), 30.0);
    assert_eq!(w(&v[8], "PROMIN"), 20.0);
    assert_eq!(w(&v[8], "ROT"), 30.0);
    assert_eq!(keys(&v[8]), ["STAY", "SEQ+", "COORD ROT"]);
}

#[test]
fn tcpm_and_m_blocks() {
    let v = run(
        "FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS REFPNT TIP-TIP\nfunction reset tcpm\nM128 F1000\nSTOP\nSTOP M0\nM8\nQ1 = 5\nL A+Q1 C-Q1 R0 FMAX M126",
    );
    assert_eq!(v[0].kind, Kind::Tcpm);
    assert_eq!(
        keys(&v[0]),
        ["F TCP", "AXIS POS", "PATHCTRL AXIS", "REFPNT TIP-TIP"]
    );
    assert_eq!(v[1].kind, Kind::TcpmReset);
    assert_eq!(v[2].kind, Kind::Empty);
    assert_eq!(v[2].m[0].0, 128);
    assert_eq!(w(&v[2], "F"), 1000.0);
    assert_eq!(v[3].kind, Kind::Stop);
    assert_eq!(v[4].kind, Kind::Stop);
    assert_eq!(v[4].m[0].0, 0);
    assert_eq!(v[5].kind, Kind::Empty);
    assert_eq!(w(&v[6], "A"), 5.0);
    assert_eq!(w(&v[6], "C"), -5.0);
}

#[test]
fn comments_headings_empty_lines_and_case() {
    let v = run(
        "0 BEGIN PGM T MM\n; a comment\n\n* - TOOL: T1\n36 * - JOB\n5 l x+1 r0 fmax ; go there \n11 ;\n99 M110; KORIVEK\nEND PGM T MM",
    );
    assert_eq!(v.len(), 2);
    assert_eq!(v[0].kind, Kind::Line);
    assert_eq!(v[0].comment.as_deref(), Some("go there"));
    assert_eq!(keys(&v[0]), ["R0", "FMAX"]);
    assert_eq!(v[1].comment.as_deref(), Some("KORIVEK"));
    assert_eq!(v[1].line, 8);
}

#[test]
fn block_skip_both_ways() {
    let text = "L X+1\n/2 L X+2\n3 /L X+3\nL X+4";
    let v = run(text);
    assert_eq!(v.len(), 2);
    let opts = fiveaxis_heidenhain::Options {
        block_skip: false,
        max_blocks: 0,
    };
    let v = common::run_with(text, fiveaxis_heidenhain::MemoryStore::new(), opts).expect("runs");
    assert_eq!(v.len(), 4);
}

#[test]
fn executed_buffers_are_reused() {
    // Two blocks in a row through the same Executed: no stale words.
    let v = run("L X+1 Y+2 Z+3 RL M3\nL X+5");
    assert_eq!(v[1].words.len(), 1);
    assert!(v[1].keys.is_empty() && v[1].m.is_empty());
}

#[test]
fn more_forms_seen_in_practice() {
    let v = run(
        "L X+1 FU0.1 FZ0.05\nTOOL CALL 5.2 Z\nCYCL CALL POS X+10 Y+10 Z+0 FMAX M3\nCYCL DEF 200 DRILLING~\n  Q206=FMAX ;F~\n  Q208=FAUTO\nL M91 Z-5\nQ1 = 2\nL  X+ 10   Y-  Q1\nCYCL DEF 10.1 IROT+30",
    );
    assert_eq!(w(&v[0], "FU"), 0.1);
    assert_eq!(w(&v[0], "FZ"), 0.05);
    assert_eq!(v[1].tool, Some(Tool::Number(5)));
    assert_eq!(keys(&v[2]), ["POS", "FMAX"]);
    assert_eq!(w(&v[2], "Z"), 0.0);
    assert_eq!(v[3].param(206), Some(f64::INFINITY));
    assert!(v[3].param(208).is_some_and(f64::is_nan));
    assert_eq!(v[4].m[0].0, 91);
    assert_eq!(w(&v[5], "X"), 10.0);
    assert_eq!(w(&v[5], "Y"), -2.0);
    let rot = v[6].word("ROT").expect("ROT");
    assert!(rot.incremental && rot.value == 30.0);
}
