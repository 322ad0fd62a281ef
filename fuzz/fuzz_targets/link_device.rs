//! The device's side of the host link: any bytes, decoded and handled as the board's
//! main loop handles them (frames, the session, a replay's steps), never panic; the
//! live tissue changes only through a checked swap; a valid `Hello` after them is
//! answered. A mesh is offered to the session before each byte (as the main loop does
//! once the tick takes one), whatever `WatchMesh` the bytes asked for.
#![no_main]
use libfuzzer_sys::fuzz_target;
use mccs::{ForceTable64, Params, SolverConfig, Wide};
use mccs_firmware::link::{Effect, Live, Mesh, Now, Replayer, Session};
use mccs_link::frame::parse;
use mccs_link::{encode, Core, Decoder, ToDevice, ToHost, MAX_FRAME};

const N: usize = mccs::topology::standard_capacity(5).0;
const E: usize = mccs::topology::standard_capacity(5).1;

fuzz_target!(|bytes: &[u8]| {
    static TABLE: std::sync::OnceLock<ForceTable64> = std::sync::OnceLock::new();
    let table = *TABLE.get_or_init(|| ForceTable64::new(&Params::TABLE2).unwrap());
    static REST: std::sync::OnceLock<Mesh<N>> = std::sync::OnceLock::new();
    let rest = *REST.get_or_init(|| {
        let topo = mccs::Topology::<N, E>::standard_patch(3, 2.5).unwrap();
        Mesh::of(&mccs::Solver::new(topo, table, &SolverConfig::default()).unwrap(), 0)
    });
    let live = Live { core: Core::M4f, grid: 3, spacing: 2.5, config: SolverConfig::default() };
    let mut session = Session::<64>::new(live, table);
    let mut replayer = Box::new(Replayer::<N, E, 64, Wide, 16>::new(false));
    let mut decoder = Decoder::new();
    let mut out = Vec::new();
    let mut hello = [0u8; MAX_FRAME];
    let hello = encode(&ToDevice::Hello, &mut hello).unwrap().to_vec();
    for (tick, &b) in bytes.iter().chain([0u8].iter()).chain(hello.iter()).enumerate() {
        session.mesh(&Mesh { tick: tick as u32, ..rest }, &mut |m: &ToHost| {
            out.push(*m);
            true
        });
        let Some(frame) = decoder.push(b) else { continue };
        match frame.and_then(parse::<ToDevice>) {
            Ok(msg) => {
                let e = session.handle(msg, Now::default(), &mut replayer, &mut |m: &ToHost| out.push(*m));
                if let Effect::Swap { set, tissue } = e {
                    session.swapped(*set.table(), tissue, &mut |m: &ToHost| out.push(*m));
                }
            }
            Err(_) => session.bad_frame(),
        }
        for _ in 0..4 {
            if !replayer.step(&mut |m: &ToHost| out.push(*m)) {
                break;
            }
        }
    }
    assert!(matches!(out.last(), Some(ToHost::Hello(_))), "{:?}", out.last());
});
