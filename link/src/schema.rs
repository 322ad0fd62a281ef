//! The protocol's version and the schema hash the handshake carries: a host and a device
//! talk only when both agree ([`crate::HelloInfo`]; the host refuses a mismatch with one
//! line saying both).
//!
//! The schema is [`SCHEMA_TEXT`], every message and field in wire order; its hash is
//! FNV-1a over that text. A change to a message changes its encoding, which the golden
//! bytes of `host-tests/tests/link/codec.rs` catch: that test fails until the text (and
//! so the hash) and the golden bytes are updated together.

/// The protocol's version: raised when a message's meaning changes.
pub const PROTOCOL: u16 = 2;

/// Every message and its fields, in wire order.
pub const SCHEMA_TEXT: &str = "\
ToDevice{Hello;Status;Arm;Disarm;Pose{origin:[i32;3]};\
TissueBegin{segments:u16,len:u32,hash:u32};TissueChunk{offset:u32,bytes:[u8]};TissueCommit;\
Watch{every:u16};ReplayBegin(ReplaySpec);ReplayPath{first:u32,points:[u8]};WatchMesh{every:u16}}\
ReplaySpec{grid:u8,spacing_mm:f64,tick_hz:f64,node_mass_kg:f64,spring_damping:f64,\
coupling_stiffness:f64,coupling_damping:f64,max_force:f64,symplectic:bool,narrow:bool,\
samples:u32,start:[f64;2],roaming:Option<RoamSpec>}\
RoamSpec{tissue_w:u8,tissue_h:u8,mu_s:f64,mu_k:f64,probe_radius:f64,cap_radius:Option<f64>}\
ToHost{Hello(HelloInfo);Ack{tissue:u32};Nak(NakReason);Status(StatusInfo);Telemetry(Telemetry);\
ReplayRow(ReplayRow);ReplayCredit{until:u32};ReplayEnd{ticks:u32};Mesh(MeshPart)}\
HelloInfo{protocol:u16,schema:u32,core:Core,tick_hz:u32,grid:u8,max_grid:u8,tissue_w:u8,\
tissue_h:u8,knots:u16,tissue:u32,path_capacity:u32}Core{M0;M3;M4f}\
NakReason{Busy;Order;Length;Hash;Segments;Table;Bound;Solver;NoTissue;Option{option:SpecOption,limit:i32}}\
SpecOption{Grid;Spacing;Rate;NodeMass;Arith;Tissue;CapRadius;Samples;Config}\
StatusInfo{ticks:u32,overruns:u32,bad_frames:u32,dropped_telemetry:u32,armed:bool,fault:bool,replaying:bool,pose:[i32;3]}\
Telemetry{seq:u32,tick:u32,probe:[i32;3],force:[i32;3],gain:u16,flags:u8,dropped:u32}\
ReplayRow{tick:u32,force:[i32;3],point:[i32;3],origin:[i32;2],max_disp:[i32;3],flags:u8,shifts:u32}\
MeshPart{seq:u32,tick:u32,first:u16,nodes:u16,positions:[[i32;3];12]}";

/// The schema's hash (FNV-1a, 32 bits, over [`SCHEMA_TEXT`]).
pub const SCHEMA: u32 = fnv1a(SCHEMA_TEXT.as_bytes());

/// FNV-1a, 32 bits.
pub const fn fnv1a(bytes: &[u8]) -> u32 {
    let mut h = 0x811C_9DC5u32;
    let mut i = 0;
    while i < bytes.len() {
        h ^= bytes[i] as u32;
        h = h.wrapping_mul(0x0100_0193);
        i += 1;
    }
    h
}
