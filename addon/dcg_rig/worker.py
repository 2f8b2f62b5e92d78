"""Run the engine in a worker thread with progress and cancellation (no `bpy`).

`dcg.extract_skeleton` releases the GIL, so Blender's UI keeps drawing while a modal
operator polls a `SkeletonJob` from a timer.
"""

import threading


class SkeletonJob:
    """One `extract_skeleton` call (or `compute`, called the same way) on a daemon thread.

    Read `stage` and `fraction` for progress, call `cancel()` to stop it at the engine's
    next check, and once `done()` read `skeleton`, or `error` (an exception; a cancelled
    run leaves `cancelled` True instead).
    """

    def __init__(self, engine, vertices, faces, options, compute=None):
        self.stage = "starting"
        self.fraction = 0.0
        self.skeleton = None
        self.error = None
        self.cancelled = False
        self._engine = engine
        self._compute = compute or engine.extract_skeleton
        self._cancel = threading.Event()
        self._thread = threading.Thread(target=self._run, args=(vertices, faces, options),
                                        name="dcg-skeleton", daemon=True)

    def start(self):
        """Start the computation."""
        self._thread.start()
        return self

    def cancel(self):
        """Ask the engine to stop at its next progress check."""
        self._cancel.set()

    def done(self):
        """Return True once the thread has finished (with a skeleton, an error or cancelled)."""
        return not self._thread.is_alive()

    def wait(self, timeout=None):
        """Block until the thread finishes or `timeout` seconds pass; return done()."""
        self._thread.join(timeout)
        return self.done()

    def _progress(self, stage, fraction):
        self.stage, self.fraction = stage, fraction
        return not self._cancel.is_set()

    def _run(self, vertices, faces, options):
        try:
            self.skeleton = self._compute(vertices, faces, progress=self._progress, **options)
        except self._engine.Cancelled:
            self.cancelled = True
        except Exception as exc:  # reported to the user by the operator
            self.error = exc
