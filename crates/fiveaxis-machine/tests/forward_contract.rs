//! `Machine::forward` turns vectors one axis at a time; the contract
//! (`machine-model.md` §3) writes it as composed maps. Both must agree.

mod common;

use common::{config, posed, sides};
use fiveaxis_machine::Side;
use proptest::prelude::*;

proptest! {
    #![proptest_config(config(1000))]

    #[test]
    fn forward_equals_the_composed_maps_of_the_contract((machine, joints, length) in posed(sides())) {
        let head = machine.chain(Side::Head, &joints);
        let table = machine.chain(Side::Table, &joints);
        let t0 = machine.tool_direction.into_inner();
        let gauge = nalgebra::Vector3::new(joints[0], joints[1], joints[2]);
        let tip_machine = gauge + head.transform_point(&(-length * t0).into()).coords;
        let tip = table.inverse_transform_point(&tip_machine.into()).coords;
        let dir = table.rotation.inverse_transform_vector(&(head.rotation * t0));
        let pose = machine.forward(&joints, length);
        prop_assert!((pose.tip - tip).norm() < 1e-9, "{:?} vs {:?}", pose.tip, tip);
        prop_assert!((pose.dir - dir).norm() < 1e-12, "{:?} vs {:?}", pose.dir, dir);
    }
}
