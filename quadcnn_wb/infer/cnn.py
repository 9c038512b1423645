"""The cnn streamline source for core.pipeline: predict labels with an ONNX model, rebuild
the streamlines from them (reconstruct), fall back per separatrix where that fails.

A model trained on one topology is refused for a domain of another (the topology
signature in its metadata must match), with a clear message.
"""

from __future__ import annotations

from .predictor import ModelError, Predictor
from .reconstruct import reconstruct_streamlines
from .signature import topology_signature


def cnn_streamlines(model_path, threads: int = 1):
    """A callable (domain, background, field) -> (streamlines, problems) for mesh_domain."""
    predictor = Predictor(model_path, threads=threads)
    expected = predictor.metadata.get("topology")

    def source(domain, background, field):
        actual = topology_signature(domain)
        if expected and expected != actual:
            raise ModelError(f"{predictor.path.name} was trained for topology {expected} "
                             f"({predictor.metadata.get('family', '?')}); this domain is "
                             f"{actual}")
        labels = predictor.field_labels(background, field)
        return reconstruct_streamlines(domain, background, field, labels)

    return source
