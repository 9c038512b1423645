"""What every benchmark shares: its options and the bundled examples it runs on."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..core.input.load import load_domain

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"


def parse_options(doc: str, argv, repeat: int):
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=2048)
    parser.add_argument("--repeat", type=int, default=repeat)
    return parser.parse_args(argv)


def model_options(doc: str, samples: int, seed: int) -> argparse.ArgumentParser:
    """The options of the benchmarks that run models on fresh family members: the models
    (default: the shipped ones), how many members, and a seed never used for training."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("models", nargs="*")
    parser.add_argument("--samples", type=int, default=samples)
    parser.add_argument("--seed", type=int, default=seed)
    return parser


def print_table_header(columns) -> None:
    """A markdown table's header and rule (the benchmarks print rows for docs/)."""
    print("| " + " | ".join(columns) + " |")
    print("|" + "---|" * len(columns))


def bundled_examples():
    """(name, domain) for every bundled example, in name order."""
    for path in sorted(EXAMPLES.glob("*.json")):
        yield path.stem, load_domain(path)
