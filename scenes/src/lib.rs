//! Scenes shared by every front end of microraster: the std host, the
//! Cortex-M firmware and the simulator draw the same triangles from here, so
//! their frames can be compared bit for bit.
//!
//! `#![no_std]`, plain constants and a few functions over the core's types.

#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

#[cfg(test)]
extern crate std;

pub mod checksum;
pub mod cubes;
