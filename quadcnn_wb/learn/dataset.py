"""Training data: many members of one shape family with their reference labels.

`quadcnn dataset FAMILY -n 2000 --seed S -o DATA.npz`.  Sample i draws everything from
the generator seeded with (S, i), so the data set is the same whatever the number of
workers.  A sample is kept only if its field has the family's singular points and its
streamlines give a valid four-sided partition; the others are dropped and counted by
reason.  Stored as one .npz: inputs `x` (points, 10) float32 — the paper's four columns
then the six ray hints of infer.rays, so one data set serves every kind of model (a
model reads the first columns it takes) —, labels `y` (points, 2) uint8, `offsets`
(samples + 1) into them, and a JSON `meta`.  The hints are computed before the smooth
deformation and bent with the sample (distances in element sizes, and labels).
"""

from __future__ import annotations

import json
import math
import multiprocessing
import os
import sys
import time
from collections import Counter
from dataclasses import dataclass

import numpy as np

from ..core.atomic import write_atomic
from ..core.field.background import background_mesh
from ..core.field.reference import numerical_reference
from ..core.input.domain import domain_from_json
from ..core.input.transform import similarity, transform_domain_json
from ..core.layout.partition import build_partition
from ..core.layout.partition_types import PartitionError
from ..infer.encoding import ENCODING, encode, swap_labels
from ..infer.rays import PAIRS, RAY_ENCODING, CrossField, field_rays, ray_features
from .augment import jitter_nodes, smooth_deformation
from .families import family

NODE_SPREAD = 0.03  # node targets vary by this share around --nodes


@dataclass
class Sample:
    x: np.ndarray  # (N, 10) float32 (older data sets: (N, 4) or (N, 8))
    y: np.ndarray  # (N, 2) uint8


@dataclass(frozen=True)
class Variants:
    """Design variants of one shape (e.g. a sketch with its dimensions varied) standing in
    for a family: sample i starts from variant i modulo their number."""

    domains: tuple  # Domain JSON dicts
    singularities: tuple  # (valence-3, valence-5) every variant must keep
    name: str = "design"


def _draw(source, rng, index):
    """(domain, singular counts it must have) for sample `index` of a family or variants."""
    if isinstance(source, Variants):
        return (domain_from_json(source.domains[index % len(source.domains)]),
                source.singularities)
    fam = family(source)
    return fam.sample(rng)[1], fam.singularities


def make_sample(source, seed: int, index: int, nodes: int = 2048):
    """(Sample, None) or (None, reason it was dropped); source: a family name or Variants."""
    rng = np.random.default_rng([seed, index])
    try:
        domain, singularities = _draw(source, rng, index)
        matrix = similarity(rng.uniform(0, 360), scale=rng.uniform(0.5, 2.0),
                            mirror=bool(rng.integers(2)))
        domain = domain_from_json(transform_domain_json(domain.to_json(), matrix))
        target = int(round(nodes * rng.uniform(1 - NODE_SPREAD, 1 + NODE_SPREAD)))
        mesh = jitter_nodes(background_mesh(domain, nodes=target), rng)
        ref = numerical_reference(domain, mesh=mesh)
    except Exception as exc:  # a generator must survive any single bad draw
        return None, f"{type(exc).__name__}"
    counts = ref.field.valences()
    if (counts[3], counts[5]) != tuple(singularities):
        return None, "singular points differ from the family's"
    if any(line.capped for line in ref.streamlines):
        return None, "a streamline had to be capped"
    try:
        build_partition(domain, ref.streamlines, mesh.element_size, flat_joints=mesh.flat_joints,
                        feature_corners=mesh.feature_corners)
    except PartitionError:
        return None, "partition not four-sided"
    hints = ray_features(mesh.nodes, mesh.triangles, ref.field.theta, field_rays(ref.field),
                         mesh.element_size, CrossField.on(mesh, ref.field.theta))
    paired = [c for pair in PAIRS for c in pair]  # hints that bend along with v1 and v2
    nodes_xy, theta, carried = smooth_deformation(
        mesh.nodes, ref.field.theta, np.column_stack([ref.labels, hints[:, paired]]), rng)
    hints[:, paired] = carried[:, 2:]
    x, swapped = encode(nodes_xy, theta, hints)
    labels = swap_labels(carried[:, :2], swapped)
    return Sample(x=x, y=np.rint(labels).astype(np.uint8)), None


def _work(args):
    return args[2], make_sample(*args)


def generate(source, n: int, seed: int, nodes: int = 2048, workers: int | None = None,
             progress=True):
    """Samples (in index order) and a Counter of drop reasons.

    progress: True for a bar on stderr, a callable (done, total) for anything else.
    """
    if not isinstance(source, Variants):
        family(source)  # fail early on an unknown family
    workers = workers or os.cpu_count() or 1
    jobs = [(source, seed, i, nodes) for i in range(n)]
    results = {}
    started = time.perf_counter()
    if workers == 1:
        iterator = map(_work, jobs)
        pool = None
    else:
        pool = multiprocessing.get_context("fork").Pool(workers)
        iterator = pool.imap_unordered(_work, jobs, chunksize=4)
    try:
        for done, (i, result) in enumerate(iterator, start=1):
            results[i] = result
            if callable(progress):
                progress(done, n)
            elif progress:
                _progress(done, n, started)
    finally:
        if pool is not None:
            pool.close()
            pool.join()
    if progress is True:
        print(file=sys.stderr)
    samples, dropped = [], Counter()
    for i in range(n):
        sample, reason = results[i]
        if sample is None:
            dropped[reason] += 1
        else:
            samples.append(sample)
    return samples, dropped


def _progress(done: int, total: int, started: float) -> None:
    width = 30
    filled = int(width * done / total)
    rate = done / max(time.perf_counter() - started, 1e-9)
    left = (total - done) / rate if rate > 0 else math.inf
    sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total} "
                     f"{rate:.1f}/s, {left:.0f}s left ")
    sys.stderr.flush()


def save_dataset(path, samples, meta: dict) -> None:
    x = np.concatenate([s.x for s in samples]) if samples else np.zeros((0, 10), np.float32)
    y = np.concatenate([s.y for s in samples]) if samples else np.zeros((0, 2), np.uint8)
    offsets = np.concatenate([[0], np.cumsum([len(s.x) for s in samples])]).astype(np.int64)
    meta = {**meta, "encoding": ENCODING, "hints": RAY_ENCODING, "samples": len(samples)}

    def write(tmp):
        with open(tmp, "wb") as handle:
            np.savez_compressed(handle, x=x, y=y, offsets=offsets, meta=json.dumps(meta))

    write_atomic(path, write)


def load_dataset(path):
    """(list of Sample, meta dict); a clear ValueError for anything that is not one."""
    try:
        with np.load(path, allow_pickle=False) as data:
            x, y, offsets = data["x"], data["y"], data["offsets"]
            meta = json.loads(str(data["meta"]))
    except FileNotFoundError:
        raise ValueError(f"{path}: no such file") from None
    except Exception as exc:
        raise ValueError(f"{path}: not a QuadCNN data set ({type(exc).__name__})") from None
    samples = [Sample(x=x[a:b], y=y[a:b]) for a, b in zip(offsets[:-1], offsets[1:])]
    return samples, meta
