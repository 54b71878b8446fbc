"""Serving the studio with uvicorn until Ctrl-C, then stopping a running simulation.

The socket is bound before anything is printed, so the URL on the first stdout line
names the real port (``--port 0`` takes a free one) and is good to open at once.
"""

from __future__ import annotations

import socket
import sys
import threading
import webbrowser
from typing import TextIO

from navseq.errors import NavseqError
from navseq.studio.app import WARM_UP_WAIT_FOR_PAGE_S, Studio, StudioConfig, create_app
from navseq.text import printable

#: Seconds uvicorn gives open connections (the live view's stream) to close on Ctrl-C.
GRACEFUL_SHUTDOWN_S = 2


def bind(host: str, port: int) -> socket.socket:
    """A listening socket on ``host``:``port`` (0: a free port), or a clear NavseqError."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except (socket.gaierror, UnicodeError) as error:
        raise NavseqError(f"cannot use host {host!r}: {error}", source="--host") from None
    family, kind, proto, _, address = infos[0]
    sock = socket.socket(family, kind, proto)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind(address)
        sock.listen(64)
    except OSError as error:
        sock.close()
        raise NavseqError(
            f"cannot listen on {host}:{port}: {error.strerror or error}", source="--port"
        ) from None
    sock.set_inheritable(True)
    return sock


def _has_display() -> bool:
    """False on a Linux machine without a graphical session (ssh, CI): nothing to open."""
    import os

    if not sys.platform.startswith("linux"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def url_of(sock: socket.socket, host: str, token: str) -> str:
    port = sock.getsockname()[1]
    shown = "127.0.0.1" if host in ("0.0.0.0", "") else "[::1]" if host == "::" else host
    if ":" in shown and not shown.startswith("["):
        shown = f"[{shown}]"
    return f"http://{shown}:{port}/?token={token}"


def serve(
    config: StudioConfig,
    host: str,
    port: int,
    *,
    open_browser: bool,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Serve until interrupted.

    Returns 0 when the server stops by itself; Ctrl-C (SIGINT, which uvicorn hands on
    once it has shut down) ends the process with 130 as for ``navseq run``, after a
    running simulation was cancelled and its report written.
    """
    import uvicorn

    out = out if out is not None else sys.stdout
    err = err if err is not None else sys.stderr
    sock = bind(host, port)
    studio = Studio(config)
    app = create_app(config, studio)
    url = url_of(sock, host, config.token)
    print(f"navseq studio: {url}", file=out, flush=True)
    if host in ("0.0.0.0", "::", ""):
        print(
            "navseq studio: warning: listening on every network interface; anyone who can "
            "reach this machine and learns the token can read and write missions under "
            f"{printable(config.roots.describe())}",
            file=err,
            flush=True,
        )
    print("navseq studio: press Ctrl-C to stop", file=err, flush=True)
    # While the browser opens: read the map, inflate it and plan the opened mission's
    # legs, so that the page's first check finds them made (a 2000 x 2000 map takes
    # over a second). The page's own requests do the same work if they come first; the
    # check waits for the page's first (its first paint comes first).
    threading.Thread(
        target=studio.warm_up,
        args=(WARM_UP_WAIT_FOR_PAGE_S,),
        name="navseq-studio-warm-up",
        daemon=True,
    ).start()
    server = uvicorn.Server(
        uvicorn.Config(
            app,
            log_level="warning",
            access_log=False,
            timeout_graceful_shutdown=GRACEFUL_SHUTDOWN_S,
            lifespan="off",
        )
    )
    if open_browser and _has_display():
        threading.Timer(0.3, webbrowser.open, args=(url,)).start()
    elif open_browser:
        print("navseq studio: no display here; open the URL above in a browser", file=err)
    try:
        server.run(sockets=[sock])
    finally:
        sock.close()
        # A running simulation is cancelled (as Ctrl-C cancels navseq run's goal) and its
        # report written before the process ends.
        if studio.run is not None and studio.run.alive:
            print("navseq studio: stopping the run and writing its report", file=err)
        studio.close()
    print("navseq studio: stopped", file=err, flush=True)
    return 0
