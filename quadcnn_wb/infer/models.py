"""Where models live and which one fits a domain.

Two folders are searched: the models shipped in `resources/models`, and a per-user folder
(user_folder.py: inside FreeCAD the folder set in the preferences, else FreeCAD's user
data folder; `$XDG_DATA_HOME/QuadCNN/models` outside; `$QUADCNN_MODELS` overriding all)
where trained-for-this-design models are saved.  A model fits a domain when the topology
signature in its metadata equals the domain's; user models win over shipped ones, so a
retrained model replaces the stock one for its topology without touching the installation.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from .predictor import ModelError, load_metadata
from .signature import topology_signature
from .user_folder import user_model_folder

SHIPPED_MODELS = Path(__file__).resolve().parents[2] / "resources" / "models"
# `auto` only takes a model this good on its test split (foreground IoU): a weaker one
# still gives a valid mesh through the numerical fallback, but slower than tracing alone.
AUTO_MIN_IOU = 0.8


@dataclass(frozen=True)
class ModelEntry:
    path: Path
    family: str
    topology: str
    origin: str  # "user" or "shipped"
    test_iou: float = 0.0  # from its metadata (0 when not recorded)


def available_models(folders=None) -> list[ModelEntry]:
    """Every readable model with a topology in its metadata, user folder first.

    A model whose metadata is unreadable is skipped here (it cannot be matched); forcing
    it with --model still reports why.
    """
    if folders is None:
        folders = [(user_model_folder(), "user"), (SHIPPED_MODELS, "shipped")]
    entries = []
    for folder, origin in folders:
        folder = Path(folder)
        if not folder.is_dir():
            continue
        for path in sorted(folder.glob("*.onnx")):
            try:
                meta = load_metadata(path)
            except ModelError:
                continue
            if meta.get("topology"):
                iou = float(meta.get("metrics_test_split", {}).get("iou", 0.0))
                entries.append(ModelEntry(path, str(meta.get("family", path.stem)),
                                          meta["topology"], origin, iou))
    return entries


def model_paths(given) -> list[Path]:
    """The model files a benchmark was given, or else every shipped one."""
    return [Path(m) for m in given] or sorted(SHIPPED_MODELS.glob("*.onnx"))


def model_for(domain, folders=None, min_iou: float = 0.0) -> ModelEntry | None:
    """The first model (user before shipped) trained on this domain's topology, among
    those whose recorded test IoU reaches min_iou (AUTO_MIN_IOU for the auto method)."""
    signature = topology_signature(domain)
    for entry in available_models(folders):
        if entry.topology == signature and entry.test_iou >= min_iou:
            return entry
    return None


def model_for_method(domain, method: str, how_to_get_one: str) -> ModelEntry | None:
    """The model the auto or cnn method takes for this domain (None: trace numerically).

    auto settles for numerical tracing when no model reaches AUTO_MIN_IOU; cnn takes any
    model of the topology and, without one, raises a ModelError saying where to put one
    and `how_to_get_one` (the command line and FreeCAD offer different ways).
    """
    if method == "numerical":
        return None
    entry = model_for(domain, min_iou=AUTO_MIN_IOU if method == "auto" else 0.0)
    if entry is None and method == "cnn":
        raise ModelError(f"no model for this domain's topology {topology_signature(domain)}: "
                         f"put one in {user_model_folder()} or {how_to_get_one}")
    return entry
