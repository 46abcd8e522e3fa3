//! The rig's wire formats, byte for byte and without I/O: the SwarmCon / CosPhi tracker stream
//! ([`swarmcon`]), the Colias serial protocol ([`colias`]) and JSON pose datagrams ([`udp_pose`]).
//! Each turns bytes into values and back; the transports move the bytes.
pub mod colias;
pub mod swarmcon;
pub mod udp_pose;
