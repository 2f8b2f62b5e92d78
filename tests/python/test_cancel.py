"""Cancel latency (issue #7): the progress callback returning False (Esc in Blender) stops
dcg.extract_skeleton, dcg.Extractor and dcg.skin_weights within 0.5 s, and leaves nothing
half-made: a later run gives the same result as an uncancelled one.

A cancel is requested either at the k-th progress call (the callback returns False right away)
or after a wall-clock delay (the callback returns False at its first call after it, so the
latency includes the wait for the engine's next poll). The latency is the time from the request
to dcg.Cancelled reaching Python. Real meshes: horse.ply (97k faces: remeshed, so stage 0 runs
its CGAL steps and the last stage builds a query on the input) and hand.obj.
"""

import time

import numpy as np
import pytest

import dcg
from conftest import shared_skeleton

LIMIT_S = 0.5


class Canceller:
    """A progress callback that records its calls and returns False once a request is due:
    at its first call with stage `stage` and a fraction of at least f (at=(stage, f); f = 0:
    the stage's boundary), or `after_s` seconds after the start."""

    def __init__(self, at=None, after_s=None):
        self.at, self.after_s = at, after_s
        self.calls = []  # (perf_counter, stage, fraction)
        self.requested = None
        self.start = time.perf_counter()

    def __call__(self, stage, fraction):
        now = time.perf_counter()
        self.calls.append((now, stage, fraction))
        if self.requested is not None:
            return True
        if self.at is not None and stage == self.at[0] and fraction >= self.at[1]:
            self.requested = now
            return False
        if self.after_s is not None and now - self.start >= self.after_s:
            self.requested = self.start + self.after_s
            return False
        return True


def cancel_latency(run, canceller):
    """Runs run(canceller); returns (latency s, stage cancelled in), or None when the request
    never came due (a faster run than the reference: fewer polls, or done before the delay).
    A request that came due must end in dcg.Cancelled."""
    canceller.start = time.perf_counter()
    try:
        run(canceller)
    except dcg.Cancelled:
        return time.perf_counter() - canceller.requested, canceller.calls[-1][1]
    assert canceller.requested is None, "the callback returned False but the run went on"
    return None


def picks_for(calls, seconds, delays, stages=True):
    """Cancel requests: with `stages`, the first call of every stage (its boundary) and, in
    stages with several calls, the point of its work its call a third of the way through came
    at (its fraction: the engine polls every few milliseconds, so a faster run makes fewer
    calls and might never make that many; it still gets that far), in pipeline order; then the
    given fractions of the run's seconds."""
    by_stage = {}
    for _, stage, fraction in calls:
        by_stage.setdefault(stage, []).append(fraction)
    picks = []
    if stages:
        for stage, fractions in by_stage.items():
            if stage != "done":
                picks.append(Canceller(at=(stage, 0.0)))
            if len(fractions) >= 6:
                picks.append(Canceller(at=(stage, fractions[len(fractions) // 3 - 1])))
    picks += [Canceller(after_s=f * seconds) for f in delays]
    return picks


def check_latencies(name, what, run, picks):
    worst, fired = {}, 0
    for canceller in picks:
        result = cancel_latency(run, canceller)
        if result is None:
            continue
        fired += 1
        latency, stage = result
        worst[stage] = max(worst.get(stage, 0.0), latency)
        assert latency < LIMIT_S, (name, what, stage, canceller.at, canceller.after_s, latency)
    assert fired >= len(picks) // 2, f"only {fired} of {len(picks)} cancel requests came due"
    print(f"\n{name}: {what}: {fired} of {len(picks)} requests came due; worst cancel "
          "latency per stage (s): " + ", ".join(f"{s} {v:.3f}" for s, v in worst.items()))


@pytest.fixture(scope="module", params=["horse.ply", "hand.obj"])
def reference(request, meshes_dir):
    """(name, V, F, uncancelled skeleton, its progress calls, its seconds)."""
    V, F = dcg.load_mesh(str(meshes_dir / request.param))
    calls = Canceller()
    start = time.perf_counter()
    skeleton = shared_skeleton(V, F, request.param, progress=calls)
    return request.param, V, F, skeleton, calls.calls, time.perf_counter() - start


def same_skeleton(a, b):
    return (np.array_equal(a.positions, b.positions) and np.array_equal(a.links, b.links)
            and list(a.kinds) == list(b.kinds))


def test_extract_skeleton_cancels_within_half_a_second(reference):
    """Wall-clock requests through the one-call API."""
    name, V, F, expected, calls, seconds = reference
    check_latencies(name, "extract_skeleton", lambda cb: dcg.extract_skeleton(V, F, progress=cb),
                    picks_for(calls, seconds, (0.1, 0.45, 0.75), stages=False))


def test_extractor_cancels_within_half_a_second_and_resumes_whole(reference):
    """One Extractor cancelled at every stage's boundary and a third of the way through its
    polls, resuming each time (the stages done are kept, the cancelled one starts over); at the
    end its skeleton equals the uncancelled one: a cancel leaves nothing half-made."""
    name, V, F, expected, calls, seconds = reference
    current = {"canceller": Canceller()}
    ex = dcg.Extractor(V, F, lambda stage, f: current["canceller"](stage, f))

    def run(canceller):
        current["canceller"] = canceller
        ex.skeleton()

    check_latencies(name, "Extractor", run, picks_for(calls, seconds, (), stages=True))
    current["canceller"] = Canceller()
    assert same_skeleton(ex.skeleton(), expected), f"{name}: a cancel left something half-made"


def test_skin_weights_cancels_within_half_a_second(reference):
    name, V, F, skeleton, _, _ = reference
    ref = Canceller()
    start = time.perf_counter()
    expected = dcg.skin_weights(V, F, skeleton, progress=ref)
    seconds = time.perf_counter() - start
    check_latencies(name, "skin_weights", lambda cb: dcg.skin_weights(V, F, skeleton, progress=cb),
                    picks_for(ref.calls, seconds, (0.2, 0.6)))
    # Nothing half-made: the same weights as the uncancelled run.
    again = dcg.skin_weights(V, F, skeleton)
    for a, b in zip(again, expected):
        assert np.array_equal(np.asarray(a), np.asarray(b))
