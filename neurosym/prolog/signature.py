"""Signatures that tell a ``.qlf`` neurosym compiled on this account from any other ``.qlf``.

A ``.qlf`` is compiled code: loading one runs whatever its source ran at load
time (directives, ``initialization/1``), so a ``.qlf`` that arrived with a KB
is as dangerous as a pickled checkpoint. A plain digest beside it would prove
nothing (whoever wrote the ``.qlf`` can write the digest too), so neurosym
signs what it compiles with an HMAC-SHA256 under a key only this user can
read: ``$NEUROSYM_KEY_FILE``, else ``$XDG_CONFIG_HOME/neurosym/qlf.key``
(``~/.config/neurosym/qlf.key``), created with mode 0600 on first use.

The signature ``<name>.qlf.sig`` (JSON) records the SHA-256 of the ``.qlf``
and of the source it was compiled from; :func:`check` recomputes both, so a
signed ``.qlf`` is also known to be fresh for its source (no mtime guessing).
A ``.qlf`` whose signature is missing, forged, made with another key, or for
other bytes is never loaded unless the user trusts it explicitly.
"""

from __future__ import annotations

import hashlib
import hmac
import json
import os
import secrets
from pathlib import Path

from neurosym.atomic import write_bytes_atomic

FORMAT = "neurosym-qlf-signature"
VERSION = 1


def key_path() -> Path:
    """Where the signing key lives (see the module docstring)."""
    explicit = os.environ.get("NEUROSYM_KEY_FILE")
    if explicit:
        return Path(explicit)
    config = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    return Path(config) / "neurosym" / "qlf.key"


def _key(create: bool) -> bytes | None:
    """The key's bytes; created (0600, never overwritten) when asked and missing."""
    path = key_path()
    try:
        return bytes.fromhex(path.read_text().strip())
    except FileNotFoundError:
        if not create:
            return None
    except (OSError, ValueError):
        return None
    try:
        path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except FileExistsError:  # another process made it first
        return _key(create=False)
    except OSError:
        return None
    with os.fdopen(fd, "w") as fh:
        fh.write(secrets.token_hex(32) + "\n")
    return _key(create=False)


def signature_path(qlf: Path | str) -> Path:
    """``kb.qlf`` -> ``kb.qlf.sig``."""
    qlf = Path(qlf)
    return qlf.with_name(qlf.name + ".sig")


def sha256(path: Path) -> str:
    """The SHA-256 of a file's bytes, hex."""
    digest = hashlib.sha256()
    with path.open("rb") as fh:
        while chunk := fh.read(1 << 20):
            digest.update(chunk)
    return digest.hexdigest()


def _mac(key: bytes, qlf_sha: str, source_sha: str) -> str:
    message = f"{FORMAT}\0{VERSION}\0{qlf_sha}\0{source_sha}".encode()
    return hmac.new(key, message, hashlib.sha256).hexdigest()


def sign(qlf: Path | str, source: Path | str) -> Path | None:
    """Write ``<qlf>.sig`` for a ``.qlf`` neurosym just compiled from ``source``.

    Returns None (and writes nothing) when no key can be read or created; such
    a ``.qlf`` is then simply never trusted, which costs speed, not safety.
    """
    return sign_digests(qlf, sha256(Path(qlf)), sha256(Path(source)))


def sign_digests(qlf: Path | str, qlf_sha: str, source_sha: str) -> Path | None:
    """Like :func:`sign`, for the SHA-256 of the very bytes compiled and written (no file read)."""
    key = _key(create=True)
    if key is None:
        return None
    body = {
        "format": FORMAT,
        "version": VERSION,
        "qlf_sha256": qlf_sha,
        "source_sha256": source_sha,
        "hmac_sha256": _mac(key, qlf_sha, source_sha),
    }
    path = signature_path(qlf)
    write_bytes_atomic(path, (json.dumps(body, indent=1) + "\n").encode())
    return path


def check(qlf: Path | str, source: Path | str | None = None) -> str | None:
    """None when ``qlf`` carries a valid signature (for ``source``, if given), else why not."""
    qlf = Path(qlf)
    qlf_sha = sha256(qlf) if qlf.is_file() else ""  # "" matches no signature
    if source is None:
        return check_digests(qlf, qlf_sha)
    source = Path(source)
    source_sha = sha256(source) if source.is_file() else ""
    return check_digests(qlf, qlf_sha, source_sha, source.name)


def check_digests(
    qlf: Path | str, qlf_sha: str, source_sha: str | None = None, source_name: str | None = None
) -> str | None:
    """Like :func:`check`, for bytes already read and hashed: None when the
    signature beside ``qlf`` vouches for ``qlf_sha`` (and ``source_sha``), else why not.

    Loading then reads those same bytes (a private copy), never ``qlf`` again.
    """
    qlf = Path(qlf)
    sig = signature_path(qlf)
    try:
        body = json.loads(sig.read_text())
    except FileNotFoundError:
        return f"it has no signature {sig.name}"
    except (OSError, ValueError):
        return f"its signature {sig.name} cannot be read"
    if not isinstance(body, dict) or body.get("format") != FORMAT:
        return f"{sig.name} is not a neurosym signature"
    key = _key(create=False)
    if key is None:
        return f"there is no signing key at {key_path()}"
    fields = [body.get(k) for k in ("qlf_sha256", "source_sha256", "hmac_sha256")]
    if not all(isinstance(f, str) for f in fields):
        return f"{sig.name} is incomplete"
    signed_qlf, signed_source, mac = fields
    if not hmac.compare_digest(_mac(key, signed_qlf, signed_source), mac):
        return f"{sig.name} was not made with this account's key"
    if qlf_sha != signed_qlf:
        return f"it is not the file {sig.name} signed"
    if source_sha is not None and source_sha != signed_source:
        return f"it was compiled from another version of {source_name or 'its source'}"
    return None
