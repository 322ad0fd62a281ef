/* A trainer scene's first lines in C: open the device, print its facts and what it kept
 * of its last run (its black box), load a tissue,
 * arm it, hold 2 s reading telemetry, move and tilt the tissue, read one mesh, disarm.
 *
 *   cargo build --release -p mccs-client
 *   gcc examples/c/scene.c -I client/include -L target/release -lmccs_client -o scene
 *   LD_LIBRARY_PATH=target/release ./scene unix:/tmp/mccs.sock   (from the repository root)
 */
#include <mccs.h>
#include <stdio.h>
#include <time.h>

static int fail(const char *what) {
    fprintf(stderr, "scene: %s: %s\n", what, mccs_last_error());
    return 1;
}

static void sleep_ms(long ms) {
    struct timespec t = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&t, NULL);
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: scene ADDR (unix:PATH, tcp:HOST:PORT or a serial port)\n");
        return 2;
    }
    mccs_device *d = NULL;
    if (mccs_open(argv[1], &d) != MCCS_OK) return fail("open");

    mccs_device_info info;
    if (mccs_info(d, &info) != MCCS_OK) return fail("info");
    printf("device: %s%s, %u Hz, %s patch %ux%u on a %ux%u tissue, clamp %.3g N, mu %.2g/%.2g\n",
           info.device_kind ? "arm" : "1-DOF", info.simulated ? " (simulated)" : "", info.tick_hz,
           info.roaming ? "roaming" : "glued", info.grid, info.grid, info.tissue_w, info.tissue_h,
           info.force_clamp_n, info.mu_s, info.mu_k);

    /* What the device kept of its run before its last reset (none after a power-on). */
    static mccs_box_tick ticks[512];
    mccs_black_box_record last;
    size_t kept = 0;
    if (mccs_black_box(d, &last, ticks, 512, &kept) != MCCS_OK) return fail("black box");
    if (last.kept)
        printf("last run: stopped by %s at tick %u, ended by %s at tick %u, %zu ticks kept\n",
               mccs_stop_cause_name(last.stopped_by), last.stop_tick,
               mccs_stop_cause_name(last.ended_by), last.end_tick, kept);
    else
        printf("last run: none kept\n");

    uint32_t hash = 0;
    if (mccs_load_tissue(d, "params/table2-stiffer.toml", 0.5, 0.4, &hash) != MCCS_OK)
        return fail("load");
    printf("tissue: %08x\n", hash);

    if (mccs_watch(d, 20) != MCCS_OK || mccs_watch_mesh(d, 50) != MCCS_OK) return fail("watch");
    if (mccs_arm(d) != MCCS_OK) return fail("arm");
    for (int k = 0; k < 20; k++) { /* 2 s, the device held armed by the library */
        sleep_ms(100);
        mccs_telemetry_sample t;
        if (mccs_telemetry(d, &t) == MCCS_OK && k % 5 == 4)
            printf("t=%.2f s probe z=%.3f mm force z=%.3f N gain=%.2f flags=%#x\n", t.received_s,
                   t.probe_mm[2], t.force_n[2], t.gain, t.flags);
    }
    if (mccs_set_pose(d, 5.0, 0.0, 0.0, 0.0, 10.0, 0.0) != MCCS_OK) return fail("pose");
    sleep_ms(300);

    mccs_mesh_node nodes[64];
    size_t count = 0;
    uint32_t seq = 0;
    if (mccs_mesh(d, nodes, 64, &count, &seq) != MCCS_OK) return fail("mesh");
    printf("mesh %u: %zu nodes, node 0 at (%u,%u) z=%.3f mm\n", seq, count, nodes[0].i, nodes[0].j,
           nodes[0].position_mm[2]);

    mccs_device_status s;
    if (mccs_disarm(d) != MCCS_OK || mccs_status(d, &s) != MCCS_OK) return fail("disarm");
    printf("status: ticks=%u overruns=%u armed=%d fault=%d\n", s.ticks, s.overruns, s.armed, s.fault);
    mccs_close(d);
    return 0;
}
