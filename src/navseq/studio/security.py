"""What the studio lets a request do: the token, the host, and the folders files may be under.

The studio runs on the user's machine with the user's rights, so a web page from
elsewhere must not be able to use it: the token (compared in constant time, and a
SameSite cookie), a ``Host`` that names this machine (a page whose domain was made to
resolve to 127.0.0.1, DNS rebinding, says its own name there: only the loopback names
and ``--host`` are taken), JSON bodies only (a
cross-site form can send ``text/plain`` without asking), and headers that keep the
page out of frames and other sites' scripts and styles out of the page
(:data:`RESPONSE_HEADERS`). The page itself may touch only the folders the user named at
start: the mission's and the map's folders, or ``--root``. A path that leaves them
(``..``, a symlink pointing out, an absolute path elsewhere) is refused with a
message saying which folders are allowed.
"""

from __future__ import annotations

import hmac
import ipaddress
import os
from collections.abc import Iterable, Sequence
from pathlib import Path

from navseq.errors import NavseqError
from navseq.text import printable

#: The cookie that carries the token after the first page load.
COOKIE_NAME = "navseq_studio_token"
#: The request header an API client may send the token in instead.
TOKEN_HEADER = "x-navseq-token"
#: Hosts a request may say it is for, besides ``--host``: this machine's loopback names.
LOCAL_NAMES = frozenset({"127.0.0.1", "localhost", "::1"})
#: ``--host`` values that listen on every interface: the machine is then reached by any
#: of its addresses, so any IP address is a host of ours (names still are not).
EVERY_INTERFACE = frozenset({"0.0.0.0", "::", ""})
#: Sent with every answer. The page loads its scripts, styles and Leaflet from the
#: studio only; styles may be inline because Leaflet positions its panes with them.
RESPONSE_HEADERS = {
    "content-security-policy": (
        "default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; "
        "img-src 'self' data: blob:; connect-src 'self'; object-src 'none'; "
        "base-uri 'none'; form-action 'self'; frame-ancestors 'none'"
    ),
    "x-content-type-options": "nosniff",
    "x-frame-options": "DENY",
    # The page's first URL carries the token: never hand it on to another site.
    "referrer-policy": "no-referrer",
}


def allowed_hosts(listen_host: str) -> frozenset[str]:
    """The hosts requests may name when the studio listens on ``listen_host``."""
    return LOCAL_NAMES | {listen_host.strip().strip("[]").lower()}


def host_allowed(host_header: str | None, hosts: frozenset[str] = LOCAL_NAMES) -> bool:
    """Whether a ``Host`` header (``name``, ``name:port``, ``[::1]:port``) is one of
    ``hosts``; with a host of :data:`EVERY_INTERFACE` among them, any IP address is."""
    if not host_header:
        return False
    host = host_header.strip().lower()
    if host.startswith("["):
        name = host[1:].partition("]")[0]
    else:
        name = host.rsplit(":", 1)[0] if host.count(":") == 1 else host
    if name in hosts:
        return True
    if hosts & EVERY_INTERFACE:
        try:
            ipaddress.ip_address(name)
        except ValueError:
            return False
        return True
    return False


def token_matches(given: str | None, expected: str) -> bool:
    """True when ``given`` is the token; the comparison takes the same time either way."""
    if not given:
        return False
    return hmac.compare_digest(given.encode("utf-8", "replace"), expected.encode("utf-8"))


class FileRoots:
    """The folders the studio may read and write files under.

    ``base`` is where relative paths start (the mission's folder). Paths are resolved
    (symlinks followed) before they are checked, so a link pointing out is refused.
    """

    def __init__(self, folders: Iterable[Path], base: Path) -> None:
        roots: list[Path] = []
        for folder in folders:
            resolved = folder.resolve()
            if resolved not in roots:
                roots.append(resolved)
        if not roots:
            raise ValueError("at least one folder is needed")
        self.folders: Sequence[Path] = tuple(roots)
        self.base = base.resolve()

    def describe(self) -> str:
        return ", ".join(printable(str(folder)) for folder in self.folders)

    def contains(self, path: Path) -> bool:
        resolved = path.resolve()
        return any(resolved == root or resolved.is_relative_to(root) for root in self.folders)

    def resolve(self, text: str, what: str, *, base: Path | None = None) -> Path:
        """The file ``text`` names (relative to ``base``, default :attr:`base`), checked.

        Raises :class:`NavseqError` naming ``what`` when the path is empty, not valid,
        or outside every allowed folder.
        """
        if not isinstance(text, str) or not text.strip():
            raise NavseqError("no file name given", source=what)
        if "\x00" in text:
            raise NavseqError("is not a valid file name (NUL byte)", source=what)
        start = base if base is not None else self.base
        candidate = Path(os.path.expanduser(text)) if text.startswith("~") else Path(text)
        if not candidate.is_absolute():
            candidate = start / candidate
        try:
            resolved = candidate.resolve()
        except (OSError, RuntimeError) as error:  # a symlink loop
            raise NavseqError(f"cannot be resolved: {error}", source=what) from None
        if not self.contains(resolved):
            raise NavseqError(
                f"{printable(text)} is outside the folders the studio may use "
                f"({self.describe()}); start it with --root to allow another folder",
                source=what,
            )
        return resolved

    def relative(self, path: Path, base: Path | None = None) -> str:
        """``path`` as the page shows it: relative to ``base`` (default :attr:`base`)."""
        return os.path.relpath(path.resolve(), base if base is not None else self.base)
