//! Cluster culling: honest and arbitrary cluster sets, arbitrary matrices
//! and cull settings (see `microraster_fuzz::clusters`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use microraster_fuzz::{run_clusters, ClusterInput};

fuzz_target!(|input: ClusterInput| run_clusters(&input));
