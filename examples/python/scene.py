#!/usr/bin/env python3
"""A trainer scene's first lines in Python: open the device, print its facts and what
it kept of its last run (its black box), load a tissue, arm it, hold 2 s reading
telemetry, move and tilt the tissue, read one mesh, disarm. From the repository root:

    cargo build --release -p mccs-client
    pip install ./client/python
    MCCS_CLIENT_LIB=target/release/libmccs_client.so python3 examples/python/scene.py unix:/tmp/mccs.sock
"""

import sys
import time

from mccs_client import Device, MccsError


def main(addr: str) -> int:
    with Device(addr) as device:
        info = device.info()
        print(f"device: {info.device}{' (simulated)' if info.simulated else ''}, {info.tick_hz} Hz, "
              f"{'roaming' if info.roaming else 'glued'} patch {info.grid}x{info.grid} on a "
              f"{info.tissue[0]}x{info.tissue[1]} tissue, clamp {info.force_clamp_n:.3g} N, mu {info.friction[0]:.2g}/{info.friction[1]:.2g}")
        last = device.black_box()  # what it kept of its run before its last reset
        print(f"last run: stopped by {last.stopped_by} at tick {last.stop_tick}, ended by {last.ended_by}, "
              f"{len(last.ticks)} ticks kept" if last.kept else "last run: none kept")
        print(f"tissue: {device.load_tissue('params/table2-stiffer.toml', friction=(0.5, 0.4)):08x}")
        device.watch(20)
        device.watch_mesh(50)
        with device.armed():
            for k in range(20):  # 2 s, the device held armed by the library
                time.sleep(0.1)
                t = device.telemetry()
                if t is not None and k % 5 == 4:
                    print(f"t={t.received_s:.2f} s probe z={t.probe_mm[2]:.3f} mm force z={t.force_n[2]:.3f} N "
                          f"gain={t.gain:.2f} contact={t.flag('contact')} slipping={t.flag('slipping')}")
            device.set_pose((5.0, 0.0, 0.0), (0.0, 10.0, 0.0))
            time.sleep(0.3)
            mesh = device.mesh()
            if mesh is None:
                print("scene: no mesh arrived", file=sys.stderr)
                return 1
            seq, nodes = mesh
            print(f"mesh {seq}: {len(nodes)} nodes, node 0 at ({nodes[0].i},{nodes[0].j}) z={nodes[0].position_mm[2]:.3f} mm")
        s = device.status()
        print(f"status: ticks={s.ticks} overruns={s.overruns} armed={int(s.armed)} fault={s.fault}")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print("usage: scene.py ADDR (unix:PATH, tcp:HOST:PORT or a serial port)", file=sys.stderr)
        sys.exit(2)
    try:
        sys.exit(main(sys.argv[1]))
    except MccsError as e:
        print(f"scene: {e}", file=sys.stderr)
        sys.exit(1)
