//! The corpus's CL file (SolidWorks CAM, 9,814 GOTOs, circles, tool
//! changes) converted end to end into machine axes for the built-in
//! swivel-head machine and judged by forward kinematics (`common::judge`):
//! every row of the output within the tolerances of the CL path at the
//! same instant (tool vectors on the great circle between GOTOs), every
//! block's time within 1 %, in each feed style that keeps the feed.

mod common;

use common::{Rules, Side, judge, run};
#[path = "../../fiveaxis-cli/tests/common/corpus.rs"]
mod corpus;

use fiveaxis_machine::{Offsets, ToolOffset, Vec3, builtin};
use fiveaxis_post::apt::to_tcpc;
use fiveaxis_post::{Axes, FeedStyle, PostOptions};

#[test]
fn the_corpus_cl_file_to_machine_axes_within_tolerance() {
    let Some(path) = corpus::corpus_path("cl_solidworks_boss.apt") else {
        return;
    };
    let apt = std::fs::read_to_string(path).expect("the corpus CL file reads");
    let program = to_tcpc(&apt, "cl_solidworks_boss.apt").expect("converts");
    let machine = builtin("head-table-bc").expect("built-in");
    let mut offsets = Offsets::default();
    for (n, length) in [(1, 76.0), (5, 90.0)] {
        offsets.tools.insert(
            n,
            ToolOffset {
                length,
                ..ToolOffset::default()
            },
        );
    }
    offsets.work[0] = Vec3::new(0.0, 0.0, 50.0);
    let segments = run(&machine, &offsets, &program, None, false).expect("runs");
    for feed in [FeedStyle::InverseTime, FeedStyle::DegreesPerMinute] {
        let options = PostOptions {
            origin: offsets.work[0],
            axes: Axes::Post { great_circle: true },
            feed,
            ..PostOptions::default()
        };
        let (text, result) = common::post(&machine, &machine, &segments, options);
        assert_eq!(result.unresolved, 0);
        assert_eq!(result.out_of_limits, 0);
        let rules = Rules::great_circle_of(&options);
        let side = |text| Side {
            machine: &machine,
            offsets: &offsets,
            text,
        };
        let w = judge(side(&program), side(&text), &rules)
            .unwrap_or_else(|e| panic!("{}", e.chars().take(3000).collect::<String>()));
        eprintln!(
            "corpus CL, {}: {} source blocks, {} out, {:?}",
            feed.name(),
            result.source_blocks,
            result.moves.len(),
            w
        );
    }
}
