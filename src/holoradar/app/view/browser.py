"""Drive the viewer in headless Chromium: for the end-to-end tests, the latency benchmark
and the documentation's screenshots.

Uses Selenium with the system's Chromium and its chromedriver (Debian's
``chromium`` and ``chromium-driver`` packages; ``make test`` installs them
where it can). :func:`find_chromium` says what is missing.

The page's state is read from the Bokeh models the page names (``peak``,
``glare_report``, ``depth``...): their text is what the page shows.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["ViewerProcess", "click_button", "find_chromium", "headless_chromium", "measure_slider",
           "model_value", "set_model", "shown_db", "wait_idle"]


def find_chromium() -> tuple[str | None, str | None, str]:
    """``(chromium, chromedriver, why)``: the executables found, and what is missing."""
    chrome = next((p for p in (os.environ.get("HOLORADAR_CHROMIUM"), shutil.which("chromium"),
                               shutil.which("chromium-browser"), shutil.which("google-chrome"))
                   if p), None)
    driver = os.environ.get("HOLORADAR_CHROMEDRIVER") or shutil.which("chromedriver")
    missing = [n for n, p in (("chromium", chrome), ("chromedriver", driver)) if not p]
    why = "" if not missing else (
        f"no {' and no '.join(missing)} on PATH (install Debian's chromium and "
        "chromium-driver, or set HOLORADAR_CHROMIUM and HOLORADAR_CHROMEDRIVER)")
    try:
        import selenium  # noqa: F401
    except ImportError:
        why = (why + "; " if why else "") + "selenium is not installed (pip install selenium)"
    return chrome, driver, why


def headless_chromium(width: int = 1600, height: int = 1000) -> Any:
    """A Selenium driver of headless Chromium with the browser console logged."""
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    chrome, driver, why = find_chromium()
    if why:
        raise RuntimeError(why)
    opts = Options()
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              f"--window-size={width},{height}", "--hide-scrollbars"):
        opts.add_argument(a)
    opts.binary_location = chrome
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(driver), options=opts)


class ViewerProcess:
    """``holoradar view ARGS --no-browser --json`` in a child process; ``url`` once ready.

    A context manager: the server is stopped on exit.
    """

    def __init__(self, args: Sequence[str], *, cwd: str | Path | None = None,
                 timeout: float = 60.0) -> None:
        cmd = [sys.executable, "-m", "holoradar", "view", *map(str, args),
               "--no-browser", "--json"]
        env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONUNBUFFERED": "1"}
        # Files, not pipes: a server that logs a lot must never block on a full pipe.
        self._out = tempfile.TemporaryFile("w+")
        self._err = tempfile.TemporaryFile("w+")
        self.proc = subprocess.Popen(cmd, stdout=self._out, stderr=self._err, cwd=cwd,
                                     env=env, text=True)
        t0 = time.monotonic()
        self.url = ""
        while time.monotonic() - t0 < timeout:
            self._out.seek(0)
            text = self._out.read()
            if text.rstrip().endswith("}"):
                try:
                    self.url = json.loads(text)["url"]
                except (json.JSONDecodeError, KeyError):
                    break
                return
            if self.proc.poll() is not None:
                break
            time.sleep(0.05)
        self.stop()
        self._out.seek(0)
        raise RuntimeError(f"holoradar view did not start: {self._out.read()} {self.log()}")

    def log(self) -> str:
        """What the server wrote to its standard error so far."""
        self._err.seek(0)
        return self._err.read()

    def stop(self) -> None:
        """Stop the server (terminate, then kill after 10 s)."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()

    def __enter__(self) -> ViewerProcess:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.stop()


_MODEL = "Bokeh.documents[0].get_model_by_name(arguments[0])"


def wait_idle(driver: Any, timeout: float = 60.0) -> None:
    """Wait until the page has drawn its first picture and no imaging is pending."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        ready = driver.execute_script(
            "const d = window.Bokeh && Bokeh.documents[0];"
            "if (!d) return false; const p = d.get_model_by_name('peak');"
            "const s = d.get_model_by_name('status');"
            "return p !== null && p.text.length > 0 && !s.text.includes('...');")
        if ready:
            return
        time.sleep(0.05)
    raise TimeoutError("the viewer page did not become ready")


def model_value(driver: Any, name: str, attr: str = "text") -> Any:
    """A property of the page's model called ``name`` (e.g. a Div's ``text``)."""
    return driver.execute_script(f"return {_MODEL}[arguments[1]];", name, attr)


_SET_JS = """
const done = arguments[arguments.length - 1];
const doc = Bokeh.documents[0];
const model = doc.get_model_by_name(arguments[0]);
const src = doc.get_model_by_name('image_source');
if (JSON.stringify(model[arguments[1]]) === JSON.stringify(arguments[2])) { done(true); return; }
const on = () => { src.change.disconnect(on); requestAnimationFrame(() => done(true)); };
src.change.connect(on);
model[arguments[1]] = arguments[2];
setTimeout(() => { src.change.disconnect(on); done(false); }, arguments[3] * 1000);
"""


def set_model(driver: Any, name: str, attr: str, value: Any, *, timeout: float = 60.0) -> None:
    """Set a widget's property as a user's action would (it reaches the server), and wait
    until the picture it causes has arrived and been painted (at once when the property
    already has that value: nothing changes).

    Raises
    ------
    TimeoutError
        No new picture within ``timeout`` seconds (the page's status says why).
    """
    driver.set_script_timeout(timeout + 5)
    if not driver.execute_async_script(_SET_JS, name, attr, value, timeout):
        status = model_value(driver, "status")
        raise TimeoutError(f"no new picture after setting {name}.{attr} = {value!r}; "
                           f"the page says: {status!r}")
    wait_idle(driver, timeout)


def shown_db(driver: Any) -> Any:
    """The plan view's picture as the page holds it: |E| in dB re its reference, a
    (ny, nx) array (rows along y, as the image is drawn)."""
    import numpy as np

    got = driver.execute_script(
        "const d = Bokeh.documents[0].get_model_by_name('image_source').data;"
        "return [Array.from(d.db[0]), d.db[0].shape];")
    return np.asarray(got[0], dtype=float).reshape(got[1])


def click_button(driver: Any, name: str) -> None:
    """Press the page's button called ``name`` (as a click on it would)."""
    driver.execute_script(
        f"const m = {_MODEL};"
        "const v = [...Bokeh.index.all_views()].find(v => v.model === m);"
        "if (!v) throw new Error('no button ' + arguments[0]); v.click();", name)


_LATENCY_JS = """
const done = arguments[arguments.length - 1];
const doc = Bokeh.documents[0];
const src = doc.get_model_by_name('image_source');
const slider = doc.get_model_by_name('depth');
const t0 = performance.now();
const on = () => {
  src.change.disconnect(on);
  const arrived = performance.now() - t0;
  // BokehJS paints in the next animation frame; this callback runs after its paint,
  // and the one after that once the frame has been shown.
  requestAnimationFrame(() => {
    const painted = performance.now() - t0;
    requestAnimationFrame(() => done([arrived, painted, performance.now() - t0]));
  });
};
src.change.connect(on);
slider.value = arguments[0];
setTimeout(() => { src.change.disconnect(on); done(null); }, 20000);
"""


def measure_slider(driver: Any, depths_cm: Sequence[float]) -> Any:
    """Milliseconds from each depth-slider move to the new picture in the browser.

    Returns
    -------
    ndarray, shape (len(depths_cm), 3)
        Per move: the new picture's data has arrived; it has been painted (the
        animation frame after its arrival); that frame has been shown (the next
        one). The last is the time a user waits.
    """
    import numpy as np

    driver.set_script_timeout(30)
    out = []
    for d in depths_cm:
        ms = driver.execute_async_script(_LATENCY_JS, float(d))
        if ms is None:
            raise TimeoutError(f"no new picture after moving the slider to {d} cm")
        out.append([float(v) for v in ms])
    return np.array(out)
