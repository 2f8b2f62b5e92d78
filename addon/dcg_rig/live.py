"""The live preview: the extractor behind the shown preview, kept for a live tau and for Rig.

Preview Skeleton keeps its `dcg.Extractor` here with what it was made from (the mesh
object's name, a fingerprint of its evaluated world-space triangles, the engine options but
tau). While the preview is shown:

- moving the panel's Tau slider re-thresholds the kept prongs (`Extractor.retune`) and
  redraws the preview from the stages after them: tens of milliseconds on a 10k-face mesh, no
  rerun of stages 0-2, 4 and 5;
- Rig with DCG on the same mesh with the same options binds the previewed skeleton instead
  of computing it again.

An edit of the mesh (another fingerprint), other options, Clear, a new preview or a loaded
file drop it; Rig then computes from scratch as always.
"""

import hashlib

import numpy as np

#: The kept preview, or None: a `Kept`.
_kept = None


class Kept:
    """A previewed extractor and what it was made from."""

    def __init__(self, mesh_name, fingerprint, options, extractor):
        self.mesh_name = mesh_name
        self.fingerprint = fingerprint
        self.options = options
        self.extractor = extractor


def fingerprint(V, F):
    """Return a digest of the triangles (V, F): an edit of the mesh changes it."""
    digest = hashlib.blake2b(digest_size=16)
    for array in (V, F):
        array = np.ascontiguousarray(array)
        digest.update(str(array.shape).encode())
        digest.update(array.tobytes())
    return digest.hexdigest()


def _but_tau(options):
    return {k: v for k, v in options.items() if k != "tau"}


def remember(mesh_name, mesh_fingerprint, options, extractor):
    """Keep the extractor that made the preview of `mesh_name` (the triangles of
    `mesh_fingerprint`) with `options`."""
    global _kept
    _kept = Kept(mesh_name, mesh_fingerprint, _but_tau(options), extractor)


def forget():
    """Drop the kept preview (Clear, a loaded file, unregistering)."""
    global _kept
    _kept = None


def kept_for(mesh_name):
    """Return the kept preview of `mesh_name`, or None."""
    return _kept if _kept is not None and _kept.mesh_name == mesh_name else None


def matching(mesh_name, V, F, options):
    """Return the kept extractor when it was made from these triangles (V, F) of `mesh_name`
    with these options (tau aside: it is retuned to options' tau here), else None. The
    triangles are fingerprinted only when the name and options match (Rig asks every time)."""
    kept = kept_for(mesh_name)
    if (kept is None or kept.options != _but_tau(options)
            or kept.fingerprint != fingerprint(V, F)):
        return None
    tau = options.get("tau")
    if tau is not None and kept.extractor.options.get("tau") != tau:
        kept.extractor.retune(tau)
    return kept.extractor
