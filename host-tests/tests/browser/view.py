#!/usr/bin/env python3
"""`mccs view` in a real browser: Debian's headless Chromium, driven over the DevTools
protocol on a pipe (`--remote-debugging-pipe`: no port, no package beyond Python's own).

    view.py MCCS (--demo | --connect ADDR) [--screenshot PNG [--settle S]]
    view.py --self-test

Starts `MCCS view … --port 0`, opens its page, and checks, each a named step:
  connects      the page's events arrive (its id, the device's facts, a status);
  draws         a screenshot is not blank, and the mesh's pixels sit where its nodes are;
  moves         two screenshots a second apart differ;
  arms          the Arm button arms the device (the status says armed), Disarm disarms;
  poses         a pose slider let go moves the tissue (the status's pose follows);
  loads         a parameter file chosen loads (the device's ack, its new hash in hello);
  watches       a second tab watches: its controls are off, and its POST is refused;
  drops         the view stopped, the page says its connection is lost.
Exit status 0 when every step passes, 1 at the first that fails (its name and why).
--screenshot keeps the `draws` step's screenshot (docs/view.png is one, after
--settle 10: the plots' 10 s filled). --self-test holds the screenshots' PNG reader
to images of random pixels, each row under one of the five filters (`self_test`).
"""
import base64
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import zlib

WIDTH, HEIGHT = 1280, 1000
BACKGROUND = (251, 251, 250)  # the 3-D view's clear colour (view.js)


class Failed(Exception):
    pass


def png_pixels(data):
    """(width, height, rows of (r, g, b)) of an 8-bit RGB or RGBA PNG, not interlaced.
    Rows filtered with None, Sub or Up are unfiltered a whole row at a time (bytewise sums
    on integers); Average and Paeth byte by byte."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise Failed("the screenshot is not a PNG")
    pos, idat, head = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos : pos + 4])
        kind, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + n]
        pos += 12 + n
        if kind == b"IHDR":
            head = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
    w, h, depth, colour, _, _, interlace = head
    if depth != 8 or colour not in (2, 6) or interlace:
        raise Failed(f"a PNG this reader does not take: depth {depth}, colour {colour}")
    bpp = 3 if colour == 2 else 4
    raw, stride, rows, prev = zlib.decompress(idat), w * bpp, [], bytes(w * bpp)
    add = bytewise_add(stride)
    for y in range(h):
        f, line = raw[y * (stride + 1)], raw[y * (stride + 1) + 1 : (y + 1) * (stride + 1)]
        if f == 1:
            # Each byte plus the one a pixel before it, decoded: a running sum per
            # channel, in log2(width) doublings.
            shift = bpp
            while shift < stride:
                line = add(line, bytes(shift) + line[:-shift])
                shift *= 2
        elif f == 2:
            line = add(line, prev)
        elif f in (3, 4):
            # The first pixel has no left neighbour (nor upper left): Average takes half
            # the byte above, Paeth the byte above.
            line = bytearray(line)
            for i in range(bpp):
                line[i] = (line[i] + (prev[i] // 2 if f == 3 else prev[i])) & 255
            if f == 3:
                for i in range(bpp, stride):
                    line[i] = (line[i] + (line[i - bpp] + prev[i]) // 2) & 255
            else:
                for i in range(bpp, stride):
                    a, b, c = line[i - bpp], prev[i], prev[i - bpp]
                    # |p − a|, |p − b|, |p − c| for Paeth's p = a + b − c.
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - c - c)
                    line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
            line = bytes(line)
        elif f != 0:
            raise Failed(f"a PNG row with filter {f}, which PNG does not define")
        rows.append(list(zip(line[0::bpp], line[1::bpp], line[2::bpp])))
        prev = line
    return w, h, rows


def bytewise_add(n):
    """A function of two `n`-byte strings: their sum byte by byte, mod 256, on two
    integers (the low 7 bits of each byte summed without reaching the next byte, the top
    bit by exclusive or)."""
    low, high = int.from_bytes(b"\x7f" * n, "big"), int.from_bytes(b"\x80" * n, "big")
    def add(x, y):
        a, b = int.from_bytes(x, "big"), int.from_bytes(y, "big")
        return (((a & low) + (b & low)) ^ ((a ^ b) & high)).to_bytes(n, "big")
    return add


class Browser:
    """Headless Chromium with the DevTools protocol on fds 3 (commands) and 4 (answers)."""

    def __init__(self):
        self.profile = tempfile.mkdtemp(prefix="mccs-view-chromium-")
        cmd_r, self.cmd_w = os.pipe()
        self.out_r, out_w = os.pipe()

        def pipes():
            os.dup2(cmd_r, 100), os.dup2(out_w, 101)
            os.dup2(100, 3), os.dup2(101, 4)

        exe = shutil.which("chromium") or shutil.which("chromium-browser")
        if not exe:
            raise Failed("no chromium: scripts/setup.sh installs Debian's")
        self.proc = subprocess.Popen(
            [exe, "--headless", "--remote-debugging-pipe", f"--user-data-dir={self.profile}",
             "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
             "--disable-quic", "--no-first-run", "--disable-background-networking",
             "--disable-component-update", "--disable-sync", f"--window-size={WIDTH},{HEIGHT}",
             "--hide-scrollbars", "about:blank"],
            preexec_fn=pipes, close_fds=False, stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(cmd_r), os.close(out_w)
        self.next_id, self.buf = 0, b""

    def call(self, method, session=None, timeout=30, **params):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params}
        if session:
            msg["sessionId"] = session
        os.write(self.cmd_w, json.dumps(msg).encode() + b"\0")
        end = time.time() + timeout
        while time.time() < end:
            while b"\0" not in self.buf:
                chunk = os.read(self.out_r, 1 << 16)
                if not chunk:
                    raise Failed(f"chromium ended during {method}")
                self.buf += chunk
            line, self.buf = self.buf.split(b"\0", 1)
            m = json.loads(line)
            if m.get("id") == self.next_id:
                if "error" in m:
                    raise Failed(f"{method}: {m['error']}")
                return m["result"]
        raise Failed(f"{method}: no answer in {timeout} s")

    def tab(self, url):
        target = self.call("Target.createTarget", url=url)["targetId"]
        return Tab(self, self.call("Target.attachToTarget", targetId=target, flatten=True)["sessionId"])

    def close(self):
        self.proc.kill()
        self.proc.wait()
        shutil.rmtree(self.profile, ignore_errors=True)


class Tab:
    def __init__(self, browser, session):
        self.b, self.s = browser, session
        self.b.call("Emulation.setDeviceMetricsOverride", self.s, width=WIDTH, height=HEIGHT,
                    deviceScaleFactor=1, mobile=False)

    def js(self, expr):
        r = self.b.call("Runtime.evaluate", self.s, expression=expr, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in r:
            raise Failed(f"{expr}: {r['exceptionDetails'].get('text')}")
        return r["result"].get("value")

    def until(self, expr, what, seconds=20):
        end = time.time() + seconds
        while time.time() < end:
            # (Before the page's script has run, its names are not there yet.)
            v = self.js(f"(() => {{ try {{ return ({expr}); }} catch (e) {{ return null; }} }})()")
            if v:
                return v
            time.sleep(0.1)
        raise Failed(f"{what}: not within {seconds} s ({expr})")

    def screenshot(self):
        return base64.b64decode(self.b.call("Page.captureScreenshot", self.s, format="png")["data"])


def start_view(mccs, device_args):
    proc = subprocess.Popen([mccs, "view", *device_args, "--port", "0"], stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    if "http://" not in line:
        proc.kill()
        raise Failed(f"mccs view did not print its address: {line!r} {proc.stderr.read()!r}")
    return proc, line.split("http://", 1)[1].split()[0]


def step_draws(tab, png_path):
    # Paused (the page's Pause button), the picture holds still while it is read; the
    # last frame drawn is on the screen once the browser has run a few more (a fixed
    # wait was too short on a loaded machine: 25 of 36 nodes matched an older frame).
    # First the camera on the window it follows (it eases there in time).
    tab.until("mccsView.settled()", "the camera on the window")
    tab.js("document.getElementById('pause').click()")
    seen = tab.js("mccsView.state.frames")
    tab.until(f"mccsView.state.frames >= {seen + 4}", "four animation frames after the pause")
    time.sleep(0.1)
    png = tab.screenshot()
    if png_path:
        with open(png_path, "wb") as f:
            f.write(png)
    w, h, rows = png_pixels(png)
    colours = {rows[y][x] for y in range(0, h, 7) for x in range(0, w, 7)}
    if len(colours) < 50:
        raise Failed(f"the screenshot is nearly blank: {len(colours)} colours")
    nodes = tab.js("mccsView.nodesOnScreen()")
    if len(nodes) < 9:
        raise Failed(f"{len(nodes)} mesh nodes")
    def near(x, y):
        return any(rows[y + dy][x + dx] != BACKGROUND for dy in (-1, 0, 1) for dx in (-1, 0, 1)
                   if 0 <= x + dx < w and 0 <= y + dy < h)
    hit = sum(near(round(x), round(y)) for x, y in nodes)
    if hit < 0.9 * len(nodes):
        raise Failed(f"only {hit} of {len(nodes)} nodes have the mesh's pixels")
    # Each triangle filled with the tissue's colour (red over green, view.js's
    # depthColour): its centroid's pixel.
    centroids = tab.js("mccsView.centroidsOnScreen()")
    filled = sum(rows[round(y)][round(x)][0] - rows[round(y)][round(x)][1] > 40 for x, y in centroids)
    if filled < 0.9 * len(centroids):
        raise Failed(f"only {filled} of {len(centroids)} triangles filled with the tissue's colour")
    # And the 3-D view's corner is background: the mesh is not everywhere.
    box = tab.js("(() => { const r = document.getElementById('scene').getBoundingClientRect(); return [r.left, r.top]; })()")
    if rows[round(box[1]) + 3][round(box[0]) + 3] != BACKGROUND:
        raise Failed("the 3-D view's corner is not its background")
    tab.js("document.getElementById('pause').click()")
    return f"{hit} of {len(nodes)} nodes on the mesh's pixels, {filled} of {len(centroids)} triangles filled; {len(colours)} colours"


def step_moves(tab):
    a = png_pixels(tab.screenshot())[2]
    time.sleep(1.0)
    b = png_pixels(tab.screenshot())[2]
    differ = sum(pa != pb for ra, rb in zip(a, b) for pa, pb in zip(ra, rb))
    if differ < 200:
        raise Failed(f"two screenshots a second apart differ in {differ} pixels")
    return f"{differ} pixels differ"


def step_arms(tab):
    tab.until("!document.getElementById('arm').disabled", "the Arm button is on")
    tab.js("document.getElementById('arm').click()")
    tab.until("mccsView.state.status && mccsView.state.status.armed", "the status says armed")
    tab.js("document.getElementById('disarm').click()")
    tab.until("mccsView.state.status && !mccsView.state.status.armed", "the status says disarmed")
    return "armed, then disarmed"


def step_poses(tab):
    tab.js("(() => { const s = document.getElementById('pose-x'); s.value = 5; s.dispatchEvent(new Event('change')); })()")
    tab.until("mccsView.state.status && Math.abs(mccsView.state.status.pose[0] - 5) < 1e-3", "the status's pose at x = 5 mm")
    return "x = 5 mm"


def step_loads(tab, params):
    before = tab.js("mccsView.state.hello.line")
    doc = tab.b.call("DOM.getDocument", tab.s)["root"]["nodeId"]
    node = tab.b.call("DOM.querySelector", tab.s, nodeId=doc, selector="#tissue-file")["nodeId"]
    tab.b.call("DOM.setFileInputFiles", tab.s, files=[os.path.abspath(params)], nodeId=node)
    answer = tab.until("(t => t.startsWith('ack') || t.startsWith('refused') || t.startsWith('failed') ? t : null)(document.getElementById('answer').textContent)",
                       "the device's answer to the load", seconds=60)
    if not answer.startswith("ack tissue="):
        raise Failed(f"the load: {answer}")
    h = answer.split("=", 1)[1]
    tab.until(f"mccsView.state.hello.line.includes('tissue_hash={h}')", "the new tissue's hash in hello")
    if f"tissue_hash={h}" in before:
        raise Failed("the hash was already live")
    return answer


def step_watches(browser, url):
    other = browser.tab(url)
    other.until("mccsView.state.id !== null && mccsView.state.holder !== null", "the second tab's welcome")
    if not other.js("document.getElementById('arm').disabled"):
        raise Failed("the second tab's Arm button is on")
    status = other.js("fetch('/arm', {method: 'POST', headers: {'X-Mccs-Page': String(mccsView.state.id)}}).then(r => r.status)")
    if status != 403:
        raise Failed(f"the second tab's POST /arm got {status}, not 403")
    return "controls off, POST /arm refused with 403"


def step_drops(tab, view):
    view.kill()
    view.wait()
    text = tab.until("(() => { const b = document.getElementById('banner'); return !b.classList.contains('hidden') && b.textContent; })()",
                     "the page says the connection is lost", seconds=10)
    if "lost" not in text:
        raise Failed(f"the banner says {text!r}")
    return repr(text)


def png_of(w, bpp, pixel_rows, filters):
    """An 8-bit RGB (`bpp` 3) or RGBA (4) PNG of `pixel_rows` (bytes, `w * bpp` each),
    row `y` filtered with `filters[y]`: PNG's filters as its specification writes them,
    each byte less its predictor from the unfiltered neighbours."""
    def predictor(f, a, b, c):
        if f == 0:
            return 0
        if f == 1:
            return a
        if f == 2:
            return b
        if f == 3:
            return (a + b) // 2
        p = a + b - c
        pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
        return a if pa <= pb and pa <= pc else b if pb <= pc else c
    raw, prev = bytearray(), bytes(w * bpp)
    for line, f in zip(pixel_rows, filters):
        raw.append(f)
        for i, x in enumerate(line):
            a = line[i - bpp] if i >= bpp else 0
            c = prev[i - bpp] if i >= bpp else 0
            raw.append((x - predictor(f, a, prev[i], c)) & 255)
        prev = line
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    head = struct.pack(">IIBBBBB", w, len(pixel_rows), 8, 2 if bpp == 3 else 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + chunk(b"IDAT", zlib.compress(bytes(raw))) + chunk(b"IEND", b"")


def self_test():
    """The PNG reader against 300 images of random pixels (1 to 80 wide, RGB and RGBA),
    their rows' filters drawn from all five: every pixel read back; and a row under a
    filter PNG does not define refused."""
    import random
    r = random.Random(2026)
    for case in range(300):
        w, h, bpp = r.randrange(1, 81), r.randrange(1, 9), r.choice((3, 4))
        rows = [bytes(r.randrange(256) for _ in range(w * bpp)) for _ in range(h)]
        filters = [r.randrange(5) for _ in range(h)]
        got = png_pixels(png_of(w, bpp, rows, filters))
        want = (w, h, [[tuple(line[x * bpp : x * bpp + 3]) for x in range(w)] for line in rows])
        if got != want:
            print(f"FAILED self-test: image {case} ({w} x {h}, {bpp} bytes a pixel, filters {filters}) read back wrong")
            return 1
    try:
        png_pixels(png_of(1, 3, [b"\0\0\0"], [5]))
        print("FAILED self-test: a row with filter 5 (none such) was read")
        return 1
    except Failed:
        pass
    print("ok self-test: 300 images, every filter, RGB and RGBA, read back; filter 5 refused", flush=True)
    return 0


def main():
    args = sys.argv[1:]
    if args == ["--self-test"]:
        return self_test()
    shot, settle = None, 0.0
    for flag in ("--screenshot", "--settle"):
        if flag in args:
            i = args.index(flag)
            if i + 1 >= len(args):
                print(f"view.py: {flag} needs a value", file=sys.stderr)
                return 2
            if flag == "--screenshot":
                shot = args[i + 1]
            else:
                settle = float(args[i + 1])
            del args[i : i + 2]
    if len(args) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    mccs, device_args = args[0], args[1:]
    step, view, browser = "starts", None, None
    try:
        view, url = start_view(mccs, device_args)
        browser = Browser()
        step = "connects"
        tab = browser.tab(f"http://{url}")
        tab.until("mccsView.state.id !== null && mccsView.state.hello && mccsView.state.status", "the page's welcome, hello and status")
        print(f"ok connects: {tab.js('mccsView.state.hello.line')[:60]}…", flush=True)
        time.sleep(settle)
        for step, run in [("draws", lambda: (tab.until("mccsView.state.meshes > 2", "a mesh"), step_draws(tab, shot))[1]),
                          ("moves", lambda: step_moves(tab)),
                          ("arms", lambda: step_arms(tab)),
                          ("poses", lambda: step_poses(tab)),
                          ("loads", lambda: step_loads(tab, "params/table2-stiffer.toml")),
                          ("watches", lambda: step_watches(browser, f"http://{url}")),
                          ("drops", lambda: step_drops(tab, view))]:
            print(f"ok {step}: {run()}", flush=True)
    except Failed as e:
        print(f"FAILED {step}: {e}", flush=True)
        return 1
    finally:
        if browser:
            browser.close()
        if view and view.poll() is None:
            view.kill()
    return 0


if __name__ == "__main__":
    sys.exit(main())
