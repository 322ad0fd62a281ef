//! The protocol's version and the schema hash the handshake carries: a host and a device
//! talk only when both agree ([`crate::info::HelloInfo`]; a host refuses a mismatch with
//! one line saying both).
//!
//! The schema is derived from the message types themselves (postcard-schema's
//! `Schema` derive on every type a message carries), and hashed the way postcard-rpc
//! keys its endpoints: FNV-1a (64 bits) over each variant's and field's name and the
//! postcard data model of its type, for [`ToDevice`] and [`ToHost`]; [`SCHEMA`] folds
//! the two keys into 32 bits with FNV-1a. A change to any message — a variant, a field,
//! a type, an order — changes the hash; nothing is written by hand.

use crate::message::{ToDevice, ToHost};
use postcard_schema::key::Key;

/// The protocol's version: raised when a message's meaning changes without its shape.
pub const PROTOCOL: u16 = 3;

/// The key of the messages to the device.
pub const TO_DEVICE_KEY: Key = Key::for_path::<ToDevice<'static>>("mccs/ToDevice");
/// The key of the messages to the host.
pub const TO_HOST_KEY: Key = Key::for_path::<ToHost>("mccs/ToHost");

/// The schema's hash: FNV-1a over the two keys' bytes.
pub const SCHEMA: u32 = {
    let mut h = mccs::fnv::Fnv1a::new();
    let (a, b) = (TO_DEVICE_KEY.to_bytes(), TO_HOST_KEY.to_bytes());
    let mut i = 0;
    while i < 8 {
        h = h.byte(a[i]);
        i += 1;
    }
    let mut i = 0;
    while i < 8 {
        h = h.byte(b[i]);
        i += 1;
    }
    h.value()
};
