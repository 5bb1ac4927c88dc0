//! Fuzz target: `aerial_chain_core::table::TableView::open` on arbitrary bytes, then every
//! lookup the units and the host make. Nothing may panic; whatever `open` accepts
//! must be readable in full.
#![no_main]

use aerial_chain_core::table::TableView;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(view) = TableView::open(data, None) else {
        return;
    };
    for k in 0..view.shape_count() {
        view.shape(k).expect("an accepted table reads every shape");
    }
    for i in 0..view.header().lsc_count as usize {
        view.lsc(i).expect("an accepted table reads every LSC entry");
    }
    view.for_each_adjacency(|_, _| {}).expect("an accepted table reads its roadmap");
    let _ = view.to_srs::<1024, 64>();
    assert!(view.shape(view.shape_count()).is_err());
});
