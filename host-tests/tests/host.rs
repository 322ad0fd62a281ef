//! The host tests, one binary (each `tests/<name>.rs` a module): one link and one
//! build of the generic core for all of them instead of one per file. Run one file's
//! tests with `cargo test -p mccs-host --test host <name>::`.

mod common;

#[path = "architecture.rs"]
mod architecture;
#[path = "arith.rs"]
mod arith;
#[path = "arm.rs"]
mod arm;
#[path = "arm_demo.rs"]
mod arm_demo;
#[path = "arm_device.rs"]
mod arm_device;
#[path = "arm_dynamics.rs"]
mod arm_dynamics;
#[path = "cap.rs"]
mod cap;
#[path = "cli/mod.rs"]
mod cli;
#[path = "contact.rs"]
mod contact;
#[path = "demo.rs"]
mod demo;
#[path = "device.rs"]
mod device;
#[path = "doc_commands.rs"]
mod doc_commands;
#[path = "doc_snippets.rs"]
mod doc_snippets;
#[path = "docs.rs"]
mod docs;
#[path = "eigenvalues.rs"]
mod eigenvalues;
#[path = "fit.rs"]
mod fit;
#[path = "float_patch.rs"]
mod float_patch;
#[path = "fuzz_inputs.rs"]
mod fuzz_inputs;
#[path = "link/mod.rs"]
mod link;
#[path = "passivity.rs"]
mod passivity;
#[path = "patch.rs"]
mod patch;
#[path = "proxy.rs"]
mod proxy;
#[path = "reference_law.rs"]
mod reference_law;
#[path = "replay.rs"]
mod replay;
#[path = "roam.rs"]
mod roam;
#[path = "scripts.rs"]
mod scripts;
#[path = "solver_properties.rs"]
mod solver_properties;
#[path = "spring_sweep.rs"]
mod spring_sweep;
#[path = "stability.rs"]
mod stability;
#[path = "swap.rs"]
mod swap;
#[path = "table_accuracy.rs"]
mod table_accuracy;
#[path = "table_bound/mod.rs"]
mod table_bound;
#[path = "table_edges.rs"]
mod table_edges;
#[path = "table_source.rs"]
mod table_source;
#[path = "tissue_pose.rs"]
mod tissue_pose;
#[path = "velocity.rs"]
mod velocity;
