"""A small headless-Chromium harness for the pytest suite: open a
self-contained local HTML file, collect its console log and take a full-page
screenshot.

It speaks the WebDriver protocol to chromedriver directly with urllib, so it
needs nothing but the Debian packages chromium and chromium-driver (numpy is
used to decode the screenshot quickly). Selenium is not used: it is not part
of the suite's dependencies (Debian does package it as python3-selenium, but
it is not installed by default and pip/PyPI may not be available), and the
half-dozen endpoints needed here are simple JSON requests.

The network is blocked (a dead proxy and a host resolver that resolves
nothing), so a page that fetches anything remote shows a console error.

    render(html_path, width=1280, timeout=60) -> dict
    python3 python/tests/browser.py PAGE.html [OUT.png]
"""

import base64
import json
import os
import pathlib
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request
import zlib

import numpy as np

INSTALL = "install the Debian packages chromium chromium-driver"


class BrowserUnavailable(RuntimeError):
    """chromium or chromedriver is missing or failed to start."""


def _binary(env, *names):
    path = os.environ.get(env)
    if path:
        if not os.access(path, os.X_OK):
            raise BrowserUnavailable(f"{env}={path} is not an executable; {INSTALL}")
        return path
    for name in names:
        found = shutil.which(name)
        if found:
            return found
    raise BrowserUnavailable(f"{names[0]} is not on PATH (nor is {env} set); {INSTALL}")


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _request(base, method, path, body=None, timeout=60):
    """One WebDriver request; returns the "value" of the JSON answer."""
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(base + path, data=data, method=method,
                                 headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return json.load(r).get("value")
    except urllib.error.HTTPError as e:
        detail = e.read().decode(errors="replace")
        try:
            v = json.loads(detail)["value"]
            detail = f"{v.get('error')}: {v.get('message', '').splitlines()[0]}"
        except (ValueError, KeyError, AttributeError, IndexError):
            pass
        raise RuntimeError(f"WebDriver {method} {path} failed ({e.code}): {detail}") from None


def _paeth(line, prior, w, bpp):
    """Undoes the Paeth filter of one row. Where the prior row is flat
    (up == upper-left) the predictor is the left byte, so those runs are
    running sums; only the other positions are walked in Python."""
    d = line.reshape(w, bpp)
    b = prior.reshape(w, bpp).astype(np.int16)
    c = np.vstack([np.zeros((1, bpp), np.int16), b[:-1]])
    sums = np.cumsum(d, axis=0, dtype=np.uint8)  # sums[j] = d[0] + ... + d[j]
    out = np.empty((w, bpp), np.uint8)
    for ch in range(bpp):
        s, bl, cl = sums[:, ch].tolist(), b[:, ch].tolist(), c[:, ch].tolist()
        dl = d[:, ch].tolist()
        steps = np.flatnonzero(b[:, ch] != c[:, ch]).tolist()
        anchor_val, anchor_sum, vals = 0, 0, []
        for j in steps:  # x[j - 1] follows from the last anchor by a running sum
            a = (anchor_val + (s[j - 1] if j else 0) - anchor_sum) & 0xFF
            bj, cj = bl[j], cl[j]
            pa, pb, pc = abs(bj - cj), abs(a - cj), abs(a + bj - 2 * cj)
            pred = a if pa <= pb and pa <= pc else (bj if pb <= pc else cj)
            anchor_val, anchor_sum = (dl[j] + pred) & 0xFF, s[j]
            vals.append(anchor_val)
        # every position: the value at its last anchor plus the sum of d since
        last, at = np.full(w, -1), np.zeros(w, np.int16)
        last[steps], at[steps] = steps, vals
        last = np.maximum.accumulate(last)
        has = last >= 0
        base = np.zeros(w, np.int16)
        base[has] = at[last[has]] - sums[last[has], ch]
        out[:, ch] = (base + sums[:, ch]) & 0xFF
    return out.reshape(w * bpp)


def _png_pixels(png, row_step=4):
    """Decodes an 8-bit RGB/RGBA non-interlaced PNG; returns (width, height,
    array of every row_step-th row, shape (rows, width, channels))."""
    if png[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, ihdr = 8, [], None
    while pos < len(png):
        length, kind = struct.unpack(">I4s", png[pos:pos + 8])
        chunk = png[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", chunk)
        elif kind == b"IDAT":
            idat.append(chunk)
        elif kind == b"IEND":
            break
        pos += 12 + length
    w, h, depth, colour, _, _, interlace = ihdr
    if depth != 8 or colour not in (2, 6) or interlace:
        raise ValueError(f"unsupported PNG (depth {depth}, colour type {colour}, interlace {interlace})")
    bpp = 3 if colour == 2 else 4
    stride = w * bpp
    raw = np.frombuffer(zlib.decompress(b"".join(idat)), np.uint8).reshape(h, stride + 1)
    filters, data = raw[:, 0], raw[:, 1:]
    out = np.empty((h, stride), np.uint8)
    prior = np.zeros(stride, np.uint8)
    for y in range(h):
        f, line = filters[y], data[y]
        if f == 0:
            cur = line
        elif f == 1:  # Sub: running sum per channel, modulo 256
            cur = np.cumsum(line.reshape(w, bpp), axis=0, dtype=np.uint8).reshape(stride)
        elif f == 2:  # Up
            cur = line + prior
        elif f == 4:
            cur = _paeth(line, prior, w, bpp)
        else:  # Avg: sequential along the row (Chromium does not emit it)
            cur, up = bytearray(line.tobytes()), prior.tolist()
            for i in range(stride):
                cur[i] = (cur[i] + (((cur[i - bpp] if i >= bpp else 0) + up[i]) >> 1)) & 0xFF
            cur = np.frombuffer(bytes(cur), np.uint8)
        out[y] = cur
        prior = out[y]
    return w, h, out[::row_step].reshape(-1, w, bpp)


def render(html_path, width=1280, timeout=60, media="screen"):
    """Opens html_path in headless Chromium; returns console, document size,
    device pixel ratio, a full-page PNG and how blank it is (see module doc).
    media="print" lays the page out as printed: print CSS, and the page's
    beforeprint handlers run."""
    url = pathlib.Path(html_path).resolve().as_uri()
    chromium = _binary("PDP_CHROMIUM", "chromium", "chromium-browser")
    driver = _binary("PDP_CHROMEDRIVER", "chromedriver")
    profile = tempfile.mkdtemp(prefix="pdp-chromium-")
    port = _free_port()
    base = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + timeout
    proc = session = None
    try:
        try:
            proc = subprocess.Popen([driver, f"--port={port}"], stdout=subprocess.DEVNULL,
                                    stderr=subprocess.DEVNULL)
        except OSError as e:
            raise BrowserUnavailable(f"cannot run {driver}: {e}; {INSTALL}") from None
        while True:
            try:
                if _request(base, "GET", "/status", timeout=2).get("ready"):
                    break
            except (OSError, RuntimeError):
                pass
            if proc.poll() is not None or time.monotonic() > deadline:
                raise BrowserUnavailable(f"{driver} did not become ready; {INSTALL}")
            time.sleep(0.05)
        caps = {"browserName": "chrome", "goog:loggingPrefs": {"browser": "ALL"},
                "timeouts": {"pageLoad": timeout * 1000, "script": timeout * 1000},
                "goog:chromeOptions": {"binary": chromium, "args": [
                    "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                    f"--window-size={width},1000", "--hide-scrollbars", "--force-device-scale-factor=1",
                    f"--user-data-dir={profile}", "--no-first-run", "--disable-extensions",
                    "--proxy-server=127.0.0.1:9", "--proxy-bypass-list=<-loopback>",
                    "--host-resolver-rules=MAP * ~NOTFOUND"]}}
        try:
            session = _request(base, "POST", "/session", {"capabilities": {"alwaysMatch": caps}},
                               timeout=timeout)["sessionId"]
        except (OSError, RuntimeError) as e:
            raise BrowserUnavailable(f"{chromium} failed to start under {driver}: {e}; {INSTALL}") from None
        sp = f"/session/{session}"

        def call(method, path, body=None):
            return _request(base, method, sp + path, body, timeout=max(1, deadline - time.monotonic()))

        def js(script, *args):
            return call("POST", "/execute/sync", {"script": script, "args": list(args)})

        call("POST", "/url", {"url": url})
        while js("return document.readyState") != "complete":
            if time.monotonic() > deadline:
                raise TimeoutError(f"{url} did not finish loading in {timeout} s")
            time.sleep(0.05)
        # let fonts load and two frames paint (scripts that draw after "load")
        call("POST", "/execute/async", {"args": [], "script": (
            "const done = arguments[arguments.length - 1];"
            "document.fonts.ready.then(() => requestAnimationFrame(() => requestAnimationFrame(done)));")})
        if media == "print":
            call("POST", "/goog/cdp/execute", {"cmd": "Emulation.setEmulatedMedia", "params": {"media": "print"}})
            js("window.dispatchEvent(new Event('beforeprint'));")
        size = js("const e = document.documentElement;"
                  "return [e.scrollWidth, e.scrollHeight, window.devicePixelRatio];")
        doc_w, doc_h, dpr = size
        shot = call("POST", "/goog/cdp/execute", {"cmd": "Page.captureScreenshot", "params": {
            "format": "png", "captureBeyondViewport": True,
            "clip": {"x": 0, "y": 0, "width": doc_w, "height": doc_h, "scale": 1}}})
        png = base64.b64decode(shot["data"])
        console = call("POST", "/se/log", {"type": "browser"})
    finally:
        if session:
            try:
                _request(base, "DELETE", f"/session/{session}", timeout=10)
            except (OSError, RuntimeError):
                pass
        if proc:
            proc.terminate()
            try:
                proc.wait(5)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        shutil.rmtree(profile, ignore_errors=True)
    w, h, rows = _png_pixels(png)
    nonwhite = float((rows[..., :3] < 245).any(axis=-1).mean()) if rows.size else 0.0
    return {"console": console, "document_width": doc_w, "document_height": doc_h,
            "device_pixel_ratio": dpr, "png": png, "png_size": (w, h),
            "nonwhite_fraction": nonwhite, "blank": nonwhite < 0.001}


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit(f"usage: {sys.argv[0]} PAGE.html [OUT.png]")
    start = time.monotonic()
    result = render(sys.argv[1])
    if len(sys.argv) == 3:
        pathlib.Path(sys.argv[2]).write_bytes(result["png"])
    shown = {k: v for k, v in result.items() if k != "png"}
    shown["seconds"] = round(time.monotonic() - start, 2)
    print(json.dumps(shown, indent=2))
