"""Stage 2b: persistent track ids for the blobs, frame after frame.

The first paper matches each label to the nearest one of the previous frame under a
distance threshold (section III-B). `BlobTracker` does that optimally
(``scipy.optimize.linear_sum_assignment``) on the horizontal distance between a
constant-velocity prediction of each track and the blob centroids, and adds what the
paper leaves out: a track survives a short disappearance, people whose blobs merge keep
their ids and their own share of the merged cells, a person cut in pieces by an occluder
stays one track, and a merged blob that splits again goes back to its owners.

Each track remembers the cells it owned in its last frame. One `BlobTracker.update`:

1. predict every live track: ``centroid + velocity * elapsed`` (horizontal velocity);
2. match: optimal one-to-one assignment of tracks to blobs on the horizontal distance
   between prediction and blob centroid, allowed within the track's gate (``gate_m``
   plus ``gate_growth`` metres per second the track has been unseen);
3. claim: a track seen in the previous frame also claims every other blob holding at
   least ``claim_share`` of its previous cells or of the blob's cells (whichever is
   smaller): this is how two people's merged blob stays both of theirs, even when each
   also has blobs of its own (a top view sees heads and shoulders merged through reaching
   arms while the legs stay apart);
4. merge: a track still without a blob (unseen for a while) follows a matched blob whose
   horizontal box (grown by ``merge_margin_m``) holds its prediction, within its gate;
5. pieces: a track's core blob is its matched blob (else the largest it claims); a blob a
   track holds alone farther than ``fragment_m`` (horizontally, centroid to centroid)
   from its core is released (someone walking away from a shared blob: the piece nearer
   the prediction kept the id); an unclaimed blob within ``fragment_m`` of a track's core
   is a fragment of that person (a body cut by an occluder, an arm seen through a gap);
   the other unclaimed blobs, largest first, start new tracks (or are fragments of a
   track started in this frame);
6. share: the cells of a blob claimed by several tracks go each to the track that owned
   the nearest cell in the previous frame (moved by its velocity; a track without cells
   there stands at its prediction); a track with less than ``min_share`` of such a blob
   loses its claim;
7. update: each track's measurement is the centroid of its cells; an alpha-beta filter
   updates the horizontal position and velocity (the second measurement of a new track
   sets its velocity directly); tracks unseen for longer than ``max_gap_s`` end.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.spatial import cKDTree

from occupose.config import BlobConfig
from occupose.grid.blobs import Blob, union_of_blobs

_INFEASIBLE = 1e9


@dataclass(frozen=True, eq=False)
class TrackState:
    """A track as of the last update.

    track_id : int, >= 1, never reused
    first_seen, last_seen : int, frame numbers (0 = the tracker's first update) when the
        track started and when it was last measured
    age : int, frames since the track started (0 in its first frame)
    centroid : (3,) float64, metres, world frame, estimated centroid of the person (of its
        own cells); horizontal part filtered, height as last measured
    velocity : (2,) float64, m/s, horizontal velocity
    predicted : (3,) float64, metres, predicted centroid at the next frame
    merged_with : tuple of int, ids of the other tracks that share a blob with it this frame
    blob : Blob, the union of the blobs it claims this frame (shared ones included), or
        None when the track was not seen in this frame
    cells : (K,) int64, flat grid indices of its own cells in its last frame (its share of
        shared blobs), increasing
    points : (K, 3) float64, metres, world frame, the centres of those cells
    """

    track_id: int
    first_seen: int
    last_seen: int
    age: int
    centroid: np.ndarray
    velocity: np.ndarray
    predicted: np.ndarray
    merged_with: tuple[int, ...]
    blob: Blob | None
    cells: np.ndarray
    points: np.ndarray


@dataclass(eq=False)
class _Track:
    track_id: int
    first_seen: int
    last_seen: int
    centroid: np.ndarray
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(2))
    hits: int = 0
    prediction: np.ndarray = field(default_factory=lambda: np.zeros(3))
    merged_with: tuple[int, ...] = ()
    blob: Blob | None = None
    cells: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    box: tuple[np.ndarray, np.ndarray] = (np.zeros(3), np.zeros(3))  # low, high of ``points``


def _number(value, what: str, low: float, high: float = np.inf, *, open_low: bool = False) -> float:
    value = float(value)
    if not (np.isfinite(value) and (value > low if open_low else value >= low) and value <= high):
        bounds = f"{'(' if open_low else '['}{low:g}, {high:g}]"
        raise ValueError(f"{what} must be a number in {bounds}, got {value!r}")
    return value


def _overlap(a: np.ndarray, b: np.ndarray) -> int:
    """Number of values common to two increasing int arrays."""
    if a.size == 0 or b.size == 0:
        return 0
    at = np.minimum(np.searchsorted(a, b), a.size - 1)
    return int(np.count_nonzero(a[at] == b))


def _boxes_touch(blob: Blob, low: np.ndarray, high: np.ndarray) -> bool:
    """Whether the blob's box and the box from ``low`` to ``high`` (3,) overlap."""
    return bool(np.all(low <= blob.high) and np.all(blob.low <= high))


class BlobTracker:
    """Persistent ids for the blobs of successive frames (see the module docstring).

    Parameters
    ----------
    fps : float, frames per second of the updates
    max_gap_s : float, seconds a track survives without a blob
    gate_m : float, metres, largest horizontal distance between a track's prediction and
        its matched blob's centroid, for a track seen in the previous frame
    gate_growth : float, metres per second of absence added to the gate
    claim_share : float in (0, 1], least overlap (share of the smaller of the track's
        previous cells and the blob's cells) for a track to claim a blob it was not matched to
    merge_margin_m : float, metres, margin of the box test of a returning track's merge
    fragment_m : float, metres, largest horizontal distance from a track's core blob to
        another blob that is a piece of the same person
    min_share : float in [0, 1], least share of a shared blob's cells a track keeps its claim with
    position_gain, velocity_gain : float in (0, 1], the gains (alpha, beta) of the
        alpha-beta filter on the horizontal position and velocity
    Defaults: the fields of :class:`occupose.config.BlobConfig`.
    """

    def __init__(self, fps: float, max_gap_s: float = BlobConfig.max_gap_s, *, gate_m: float = BlobConfig.gate_m,
                 gate_growth: float = BlobConfig.gate_growth, claim_share: float = BlobConfig.claim_share,
                 merge_margin_m: float = BlobConfig.merge_margin_m, fragment_m: float = BlobConfig.fragment_m,
                 min_share: float = BlobConfig.min_share, position_gain: float = BlobConfig.position_gain,
                 velocity_gain: float = BlobConfig.velocity_gain):
        self.fps = _number(fps, "fps", 0, open_low=True)
        self.max_gap_s = _number(max_gap_s, "max_gap_s", 0)
        self.gate_m = _number(gate_m, "gate_m", 0, open_low=True)
        self.gate_growth = _number(gate_growth, "gate_growth", 0)
        self.claim_share = _number(claim_share, "claim_share", 0, 1, open_low=True)
        self.merge_margin_m = _number(merge_margin_m, "merge_margin_m", 0)
        self.fragment_m = _number(fragment_m, "fragment_m", 0)
        self.min_share = _number(min_share, "min_share", 0, 1)
        self.position_gain = _number(position_gain, "position_gain", 0, 1, open_low=True)
        self.velocity_gain = _number(velocity_gain, "velocity_gain", 0, 1, open_low=True)
        self.frame = -1  # number of the last update
        self._tracks: dict[int, _Track] = {}
        self._next_id = 1

    @property
    def max_gap_frames(self) -> int:
        """Frames a track may go unseen and still continue."""
        return int(round(self.max_gap_s * self.fps))

    @property
    def states(self) -> dict[int, TrackState]:
        """Every live track (seen this frame or within the gap), by increasing id."""
        out = {}
        for tid, tr in sorted(self._tracks.items()):
            predicted = tr.centroid.copy()
            predicted[:2] += tr.velocity * (self.frame + 1 - tr.last_seen) / self.fps
            out[tid] = TrackState(
                track_id=tid, first_seen=tr.first_seen, last_seen=tr.last_seen,
                age=self.frame - tr.first_seen, centroid=tr.centroid.copy(), velocity=tr.velocity.copy(),
                predicted=predicted, merged_with=tr.merged_with, blob=tr.blob, cells=tr.cells, points=tr.points,
            )
        return out

    def _gate(self, track: _Track) -> float:
        return self.gate_m + self.gate_growth * (self.frame - track.last_seen - 1) / self.fps

    def update(self, blobs: Sequence[Blob]) -> dict[int, Blob]:
        """Track one frame's blobs.

        blobs : the frame's Blob list (from `blobs_from_mask`)
        Returns ``{track_id: Blob}`` for the tracks seen in this frame, ids increasing:
        each track's claimed blobs as one Blob (`union_of_blobs`, whose ``labels`` list
        them); a label in several tracks' Blobs is a blob they share.
        """
        blobs = list(blobs)
        if not all(isinstance(b, Blob) for b in blobs):
            raise ValueError(f"blobs must be Blob objects, got {[type(b).__name__ for b in blobs]}")
        self.frame += 1
        tracks = list(self._tracks.values())
        for tr in tracks:
            tr.prediction = tr.centroid.copy()
            tr.prediction[:2] += tr.velocity * (self.frame - tr.last_seen) / self.fps
            tr.blob, tr.merged_with = None, ()
        claims: dict[int, list[_Track]] = {c: [] for c in range(len(blobs))}
        core = self._match_and_claim(tracks, blobs, claims)
        self._release(blobs, claims, core)
        self._fragments_and_births(blobs, claims, core)
        owned: dict[int, list[np.ndarray]] = {}  # track id -> arrays of indices into its blobs' cells
        for c, claimers in claims.items():
            self._share(blobs[c], claimers, owned)
        for tr in list(self._tracks.values()):
            mine = [c for c, claimers in claims.items() if tr in claimers]
            if not mine:
                continue
            tr.blob = union_of_blobs([blobs[c] for c in mine])
            cells = np.concatenate([blobs[c].cells[i] for c, i in zip(mine, owned[tr.track_id])])
            points = np.concatenate([blobs[c].centers[i] for c, i in zip(mine, owned[tr.track_id])])
            order = np.argsort(cells, kind="stable")
            tr.cells, tr.points = cells[order], points[order]
            tr.cells.setflags(write=False)
            tr.points.setflags(write=False)
            tr.box = (tr.points.min(axis=0), tr.points.max(axis=0))
            self._measure(tr, tr.points.mean(axis=0))
        for c, claimers in claims.items():
            for tr in claimers:
                others = {o.track_id for o in claimers if o is not tr}
                tr.merged_with = tuple(sorted(set(tr.merged_with) | others))
        for tid in [tid for tid, tr in self._tracks.items() if self.frame - tr.last_seen > self.max_gap_frames]:
            del self._tracks[tid]
        return {tid: tr.blob for tid, tr in sorted(self._tracks.items()) if tr.blob is not None}

    def _match_and_claim(self, tracks: list[_Track], blobs: list[Blob],
                         claims: dict[int, list[_Track]]) -> dict[int, int]:
        """Steps 2-4: matched blobs, overlap claims and merges of returning tracks.

        Returns each claiming track's core blob (track id -> blob index): its matched blob,
        else the largest it claims."""
        if not tracks or not blobs:
            return {}
        pred = np.array([tr.prediction[:2] for tr in tracks])
        cost = np.linalg.norm(pred[:, None] - np.array([b.centroid[:2] for b in blobs])[None], axis=2)
        gates = np.array([self._gate(tr) for tr in tracks])
        rows, cols = linear_sum_assignment(np.where(cost <= gates[:, None], cost, _INFEASIBLE))
        matched = {}
        for r, c in zip(rows, cols):
            if cost[r, c] <= gates[r]:
                claims[c].append(tracks[r])
                matched[r] = c
        for r, tr in enumerate(tracks):
            if tr.last_seen != self.frame - 1 or tr.cells.size == 0:
                continue
            for c, blob in enumerate(blobs):
                if matched.get(r) == c or not _boxes_touch(blob, *tr.box):
                    continue
                common = _overlap(tr.cells, blob.cells)
                if common > 0 and common >= self.claim_share * min(tr.cells.size, blob.cell_count):
                    claims[c].append(tr)
        claimed = {id(tr) for group in claims.values() for tr in group}
        taken = [c for c, group in claims.items() if group]
        for r, tr in enumerate(tracks):
            if id(tr) in claimed:
                continue
            best, best_cost = None, np.inf
            for c in taken:
                inside = np.all((blobs[c].low[:2] - self.merge_margin_m <= tr.prediction[:2])
                                & (tr.prediction[:2] <= blobs[c].high[:2] + self.merge_margin_m))
                if inside and cost[r, c] <= gates[r] and cost[r, c] < best_cost:
                    best, best_cost = c, cost[r, c]
            if best is not None:
                claims[best].append(tr)
        core = {tracks[r].track_id: c for r, c in matched.items()}
        for c in sorted(claims, key=lambda c: -blobs[c].cell_count):
            for tr in claims[c]:
                core.setdefault(tr.track_id, c)
        return core

    def _release(self, blobs: list[Blob], claims: dict[int, list[_Track]], core: dict[int, int]) -> None:
        """Step 5a: a blob a track holds alone, farther than ``fragment_m`` from its core
        blob, is not that person's (someone who walked away from a shared blob): let it go."""
        for c, group in claims.items():
            if len(group) == 1 and core[group[0].track_id] != c:
                gap = np.linalg.norm(blobs[c].centroid[:2] - blobs[core[group[0].track_id]].centroid[:2])
                if gap > self.fragment_m:
                    group.clear()

    def _fragments_and_births(self, blobs: list[Blob], claims: dict[int, list[_Track]], core: dict[int, int]) -> None:
        """Step 5b: unclaimed blobs become fragments of a track whose core blob is near, or new tracks."""
        for c in sorted((c for c, group in claims.items() if not group), key=lambda c: -blobs[c].cell_count):
            blob = blobs[c]
            near = [(np.linalg.norm(blob.centroid[:2] - blobs[k].centroid[:2]), tid) for tid, k in core.items()]
            if near and min(near)[0] <= self.fragment_m:
                claims[c].append(self._tracks[min(near)[1]])
                continue
            tr = _Track(self._next_id, self.frame, self.frame, blob.centroid.copy())
            tr.prediction = blob.centroid.copy()
            self._next_id += 1
            self._tracks[tr.track_id] = tr
            claims[c].append(tr)
            core[tr.track_id] = c

    def _share(self, blob: Blob, claimers: list[_Track], owned: dict[int, list[np.ndarray]]) -> None:
        """Step 6: give each claimer of ``blob`` its cells (indices into ``blob.cells``)."""
        claimers[:] = list(dict.fromkeys(claimers))  # one claim per track
        everything = np.arange(blob.cell_count)
        while len(claimers) > 1:
            refs, whose = [], []
            for k, tr in enumerate(claimers):
                if tr.last_seen == self.frame - 1 and tr.points.size:
                    moved = tr.points.copy()
                    moved[:, :2] += tr.velocity / self.fps
                else:
                    moved = tr.prediction[None]
                refs.append(moved)
                whose.append(np.full(len(moved), k))
            _, nearest = cKDTree(np.concatenate(refs)).query(blob.centers)
            owner = np.concatenate(whose)[nearest]
            counts = np.bincount(owner, minlength=len(claimers))
            weakest = int(np.argmin(counts))
            if counts[weakest] >= max(1, self.min_share * blob.cell_count):
                for k, tr in enumerate(claimers):
                    owned.setdefault(tr.track_id, []).append(everything[owner == k])
                return
            del claimers[weakest]
        for tr in claimers:
            owned.setdefault(tr.track_id, []).append(everything)

    def _measure(self, track: _Track, measured: np.ndarray) -> None:
        """Alpha-beta update of a track from its measured centroid (3,) metres."""
        if track.hits == 0:  # a new track: its first measurement
            track.centroid = measured.copy()
        elif track.hits == 1:
            track.velocity = (measured[:2] - track.centroid[:2]) * self.fps / (self.frame - track.last_seen)
            track.centroid = measured.copy()
        else:
            residual = measured[:2] - track.prediction[:2]
            track.velocity = track.velocity + self.velocity_gain * residual * self.fps / (self.frame - track.last_seen)
            track.centroid = np.array([*(track.prediction[:2] + self.position_gain * residual), measured[2]])
        track.hits += 1
        track.last_seen = self.frame
