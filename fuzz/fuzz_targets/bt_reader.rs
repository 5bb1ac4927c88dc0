//! Fuzz target: OctoMap `.bt`/`.ot` reading must never panic, and whatever it accepts must
//! survive a write/read round trip unchanged.
#![no_main]

use aerial_chain::map::OcTree;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(tree) = OcTree::from_bt_bytes(data, "fuzz-input") {
        let (occupied, free) = tree.counts();
        assert_eq!(tree.leaves().count(), occupied + free);
        let bytes = tree.to_bt_bytes();
        let again =
            OcTree::from_bt_bytes(&bytes, "fuzz-rewrite").expect("our own output reads back");
        assert!(again == tree, "round trip changed the tree");
        if let Some((min, max)) = tree.metric_bounds() {
            let mid = [
                (min[0] + max[0]) / 2.0,
                (min[1] + max[1]) / 2.0,
                (min[2] + max[2]) / 2.0,
            ];
            let _ = tree.query(mid);
            let _ = tree.query(min);
            let _ = tree.query(max);
        }
    }
});
