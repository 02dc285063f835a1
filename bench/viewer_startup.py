"""Start-up to first frame of `adfkit view` on the bundled suturing scene: from the command's
start to its address printed (scene validated, world built, meshes sent), and to the first
picture of the bodies in headless Chromium (software WebGL), polled every 100 ms.

    .venv/bin/python bench/viewer_startup.py [RUNS]

Needs the system's Chromium (apt-get install chromium) and playwright. Asserts nothing.
"""

from __future__ import annotations

import shutil
import socket
import statistics
import subprocess
import sys
import time
from io import BytesIO
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
FLAGS = ["--headless=new", "--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]


def _port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def one(browser) -> tuple[float, float]:
    from PIL import Image

    port = _port()
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        [sys.executable, "-m", "adfkit", "view", str(ROOT / "sample_scenes" / "suturing"), "--port", str(port)],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        for line in proc.stdout:
            if line.startswith("adfkit view:"):
                break
        ready = time.perf_counter() - t0
        page = browser.new_page(viewport={"width": 1280, "height": 800})
        page.goto(f"http://127.0.0.1:{port}/")
        while True:
            png = page.screenshot(clip={"x": 0, "y": 160, "width": 900, "height": 600})
            img = np.asarray(Image.open(BytesIO(png)).convert("RGB"))
            if len(np.unique(img.reshape(-1, 3), axis=0)) > 200:
                break
            if time.perf_counter() - t0 > 120:
                raise TimeoutError("no picture in 120 s")
            page.wait_for_timeout(100)
        first = time.perf_counter() - t0
        page.close()
        return ready, first
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def main() -> int:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        print("no Chromium here: apt-get install chromium")
        return 0
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium, args=FLAGS)
        got = [one(browser) for _ in range(runs)]
        browser.close()
    ready = statistics.median(r for r, _ in got)
    first = statistics.median(f for _, f in got)
    print(
        f"adfkit view, bundled suturing scene, median of {runs}: address printed {ready:.2f} s, "
        f"first picture in headless Chromium (software WebGL) {first:.2f} s after the command started"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
