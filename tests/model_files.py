"""Model files rewritten by tests as a forger would: members changed and the digest recomputed to match.

The digest (``digest.json``, :func:`greybox.models.files.digest_document`) catches a member changed by
hand; one who knows the format recomputes it, and then the checks behind it must still refuse what is
hostile. Tests of those checks write their files with :func:`write_members`.
"""

from __future__ import annotations

import zipfile

from greybox.models.files import DIGEST_MEMBER, digest_document


def write_members(path, members: dict, *, duplicates=(), compression=zipfile.ZIP_STORED, key=None):
    """Write ``members`` (name -> bytes, any digest among them dropped) and a digest recomputed over them.

    Parameters
    ----------
    path : path-like
        The model file to write.
    members : dict of str to bytes
        Its members.
    duplicates : sequence of (str, bytes), default ()
        Members written a second time, after the others.
    compression : int, default zipfile.ZIP_STORED
        Compression of the members.
    key : bytes, optional
        Key to sign the digest with.
    """
    kept = {name: data for name, data in members.items() if name != DIGEST_MEMBER}
    with zipfile.ZipFile(path, "w", compression) as archive:
        for name, data in list(kept.items()) + list(duplicates):
            archive.writestr(name, data)
        archive.writestr(DIGEST_MEMBER, digest_document(kept, key))
    return path
