//! The wire-protocol layer of the ColCOSPhi hardware bridge: the SwarmCon / CosPhi tracker stream,
//! JSON pose datagrams, the Colias serial protocol, and the transports that carry them.

pub mod colias;
pub mod swarmcon;
pub mod udp_pose;
