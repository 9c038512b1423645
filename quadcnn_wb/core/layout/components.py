"""Connected components by union-find over hashable items: which loops the cuts have
tied together (cuts.py), which boundary nodes no-segment arcs join and which anchors a
set of merges puts in one place (collapse.py).  Items never seen are their own
component, so callers need not list them first."""

from __future__ import annotations


class Components:
    def __init__(self):
        self.parent: dict = {}

    def find(self, x):
        self.parent.setdefault(x, x)
        while self.parent[x] != x:
            self.parent[x] = self.parent[self.parent[x]]
            x = self.parent[x]
        return x

    def union(self, a, b):
        self.parent[self.find(a)] = self.find(b)
