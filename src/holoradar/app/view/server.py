"""Serve the viewer: a Bokeh server in this process, bound to the loopback by default.

Why Bokeh: one well-kept dependency (Bokeh on Tornado) that starts in about a
second, keeps the imaging in this Python process and sends each new picture
to the page as a binary array over its websocket (no image encoding, no
polling); its widgets, hover readout and colour bars are what the page needs.
The server serves BokehJS's own static files and the page: no route takes a
path from a request, so only the files given on the command line are read.
"""

from __future__ import annotations

import errno
import ipaddress
import warnings
import webbrowser
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .session import ViewSession
from .settings import ViewSettings

__all__ = ["is_loopback", "make_server", "open_in_browser", "url_of"]


def is_loopback(host: str) -> bool:
    """True for 127.0.0.0/8, ::1 and ``localhost``.

    Examples
    --------
    >>> is_loopback("127.0.0.1"), is_loopback("0.0.0.0"), is_loopback("localhost")
    (True, False, True)
    """
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def make_server(session: ViewSession, settings: ViewSettings, *, host: str = "127.0.0.1",
                port: int = 0, export_dir: Path | None = None,
                ground_file: dict[str, Any] | None = None, objects: Any = None,
                find: bool = False) -> Any:
    """A started ``bokeh.server.server.Server`` showing ``session`` at ``/``.

    Parameters
    ----------
    session, settings
        The data and the first look (each new tab starts from it).
    host : str
        Address to bind; a non-loopback one exposes the data to the network
        (a :class:`UserWarning` says so).
    port : int
        0 (default): a free port chosen by the system (``server.port``).
    export_dir : Path
        Where the page's export buttons write; default the current folder.
    objects : pandas.DataFrame, optional
        Objects overlaid and listed from the start (``holoradar detect``'s table).
    find : bool
        Each new tab finds the objects in its first plane.

    Returns
    -------
    bokeh.server.server.Server
        Started; run ``server.io_loop.start()`` to serve (blocks), ``server.stop()``
        to end.

    Raises
    ------
    ValueError
        An IPv6 address other than ``::`` as ``host``.
    OSError
        The address cannot be bound (a name that does not resolve, a port in use).
    """
    from bokeh.application import Application
    from bokeh.application.handlers.function import FunctionHandler
    from bokeh.server.server import Server

    from .page import ViewerPage

    if ":" in host and host != "::":
        # Bokeh checks the page's websocket origin as name:port, which an IPv6 address
        # cannot be written in.
        raise ValueError(f"host: an IPv6 address ({host}) cannot be served: give 127.0.0.1, "
                         "localhost, 0.0.0.0, :: or a host name")
    if not is_loopback(host):
        warnings.warn(f"serving on {host}, not the loopback: anyone who can reach this "
                      "machine can see the data and use the page", UserWarning, stacklevel=2)
    folder = Path.cwd() if export_dir is None else Path(export_dir)

    def make_doc(doc: Any) -> None:
        ViewerPage(doc, session, settings, folder, ground_file, objects=objects, find=find)

    app = Application(FunctionHandler(make_doc))
    # A free port is found, then bound by the server: another program may take it in
    # between, so a port chosen here is chosen again when that happens.
    for attempt in range(5):
        at = port or _free_port(host)
        origins = [f"{n}:{at}" for n in _names_of(host)]
        try:
            server = Server({"/": app}, address=host, port=at,
                            allow_websocket_origin=origins, num_procs=1)
            break
        except OSError as exc:
            if port or exc.errno != errno.EADDRINUSE or attempt == 4:
                raise
    server.start()
    return server


def _free_port(host: str) -> int:
    """A port the system says is free on ``host`` (taken again at once by the server)."""
    import socket

    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as sock:
        sock.bind((host, 0))
        return int(sock.getsockname()[1])


def _names_of(host: str) -> list[str]:
    """The names a browser may use for this server (its websocket ``Origin``): the host
    itself, and for the loopback ``localhost``; for a wildcard address (0.0.0.0, ::) the
    machine's name and addresses, since the server answers on all of them."""
    import socket

    names = [host]
    if is_loopback(host):
        names += ["localhost", "127.0.0.1"]
    if host in ("0.0.0.0", "::", ""):
        me = socket.gethostname()
        names += [me, socket.getfqdn(), "localhost", "127.0.0.1"]
        try:
            # IPv4 only: an IPv6 address cannot be an origin (see make_server)
            names += sorted({str(a[4][0]) for a in socket.getaddrinfo(me, None,
                                                                      socket.AF_INET)})
        except OSError:  # a machine without a resolvable name: its name must do
            pass
    return list(dict.fromkeys(n for n in names if n and ":" not in n))


def url_of(server: Any, host: str) -> str:
    """The page's address (for a wildcard host, under the machine's name)."""
    import socket

    name = socket.gethostname() if host in ("0.0.0.0", "::", "") else host
    return f"http://{name}:{server.port}/"


def open_in_browser(url: str, opener: Callable[[str], Any] = webbrowser.open) -> None:
    """Open ``url`` in the user's browser (nothing happens where there is none)."""
    try:
        opener(url)
    except Exception:  # no browser on a headless machine: the URL was printed
        pass
