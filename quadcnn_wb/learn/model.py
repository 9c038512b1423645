"""The network of the paper's §3.1 and Table 1, in PyTorch.

How the inconsistencies of Table 1 are resolved here:
- Input: one point per background node, (x, y, v1x, v1y) (see infer.encoding); Table 1's
  [B, 2048, 4] read literally.  Inside, a fixed layer adds (cos 4t, sin 4t) of the frame
  angle (see with_quartic), so the first stages see 6 channels.  Output: two logits per
  point, the labels of v1 and v2 (Table 1's [B, 2048, 2]); a sigmoid makes them
  probabilities (in the loss, and in the exported ONNX graph).
- EdgeConv (Wang et al., DGCNN): edge features [x_j - x_i, x_i] over the k = 10 nearest
  neighbours (the point itself included), a shared 1x1 convolution, max over neighbours.
  Table 1 lists the edge-feature width as the stage's input width; with [x_j - x_i, x_i]
  it is twice that, which is what this code uses.  The neighbours are found once, on the
  positions (a static graph): the frame field varies smoothly, so neighbourhoods in space
  are the meaningful ones, and kNN is the costly part.
- Each stage concatenates its EdgeConv and its plain 1x1 convolution (16, 32, 64 channels
  each), so a stage outputs 32, 64, 128 channels and the three together 224 (Table 1's
  "Concat4" 112 counts one branch per stage).
- Table 1's max pool goes from 112 (here 224) to 512 channels, which a pool cannot do: a
  1x1 convolution to 512 precedes the global max pool.  The 512-wide global feature is
  expanded to every point and joined with the 224 per-point features (736 channels).
- Head: 1x1 convolutions 256, 256 (dropout 0.5 after each), 128, 2, with batch norm and
  ReLU between them.  About 420k parameters.
Options beyond Table 1 (all off by default, so QuadCNN() is the paper's network; the
"fast" training recipe turns them on, see learn.train): Fourier features of the
positions, keypoint pooling (soft-argmax locations the head sees offsets to), a mean-pooled
half of the global feature, a dynamic graph for stages 2 and 3 (DGCNN), lighter widths,
and `inputs=8` or `10`: the first four or all six ray hints of infer.rays after the
paper's four columns.
kNN uses topk on minus the squared distance from batched matrix products (no cdist, no
Python loop over points), so any number of points N works, in training and in ONNX.
"""

from __future__ import annotations

import torch
from torch import nn

K_NEIGHBOURS = 10
STAGE_WIDTHS = (16, 32, 64)
GLOBAL_WIDTH = 512


def knn(pos: torch.Tensor, k: int) -> torch.Tensor:
    """(B, N, k) indices of the k nearest points (self included) of each point."""
    square = (pos * pos).sum(dim=-1)
    dist = square.unsqueeze(2) - 2.0 * pos @ pos.transpose(1, 2) + square.unsqueeze(1)
    return torch.topk(-dist, k, dim=-1).indices


class EdgeConv(nn.Module):
    def __init__(self, cin: int, cout: int):
        super().__init__()
        self.mlp = nn.Sequential(nn.Conv2d(2 * cin, cout, 1, bias=False),
                                 nn.BatchNorm2d(cout), nn.LeakyReLU(0.2))

    def forward(self, x: torch.Tensor, idx: torch.Tensor) -> torch.Tensor:
        b, c, n = x.shape
        k = idx.shape[-1]
        points = x.transpose(1, 2)  # (B, N, C)
        gathered = torch.gather(points, 1, idx.reshape(b, n * k, 1).expand(b, n * k, c))
        neighbours = gathered.reshape(b, n, k, c)
        centre = points.unsqueeze(2).expand(b, n, k, c)
        edges = torch.cat([neighbours - centre, centre], dim=-1).permute(0, 3, 1, 2)
        return self.mlp(edges).max(dim=-1).values  # (B, cout, N)


def _pointwise(cin: int, cout: int) -> nn.Sequential:
    return nn.Sequential(nn.Conv1d(cin, cout, 1, bias=False), nn.BatchNorm1d(cout),
                         nn.LeakyReLU(0.2))


def with_quartic(x: torch.Tensor) -> torch.Tensor:
    """(B, N, 4) -> (B, N, 6): adds cos 4t and sin 4t of the frame angle t.

    v1 = (cos t, sin t) jumps by a quarter turn wherever t crosses ±45°, lines that mean
    nothing; (cos 4t, sin 4t) is the same for the whole cross and smooth except at the
    singular points, where it winds — the structure the network has to find.
    """
    c, s = x[..., 2], x[..., 3]
    cos4 = 1.0 - 8.0 * c * c * s * s
    sin4 = 4.0 * c * s * (c * c - s * s)
    return torch.cat([x, cos4.unsqueeze(-1), sin4.unsqueeze(-1)], dim=-1)


def fourier_features(xy: torch.Tensor, octaves: int) -> torch.Tensor:
    """(B, N, 2) -> (B, N, 4 * octaves): sin and cos of 2^j pi x and y.

    The labels are bands about one element wide; a ReLU network fed raw coordinates
    learns such sharp functions of position slowly (spectral bias), with these at once.
    """
    if octaves == 0:
        return xy[..., :0]
    scales = (2.0 ** torch.arange(octaves, dtype=xy.dtype)) * torch.pi
    angles = (xy.unsqueeze(-1) * scales).flatten(-2)
    return torch.cat([torch.sin(angles), torch.cos(angles)], dim=-1)


def keypoint_offsets(scores: torch.Tensor, pos: torch.Tensor) -> torch.Tensor:
    """(B, K, N) scores, (B, N, 2) positions -> (B, 2K, N) offsets to K soft keypoints.

    Each channel's softmax over the points places one keypoint (a soft argmax); every
    point then sees where it lies relative to each.  Streamlines are field lines through
    singular points and concave corners, so "level with that point" is most of what a
    label says; with plain max pooling the head must learn coordinates of such points
    through the one point that wins each channel, which is slow to train.
    """
    weights = torch.softmax(scores, dim=-1)
    centres = weights @ pos  # (B, K, 2)
    offsets = pos.unsqueeze(1) - centres.unsqueeze(2)  # (B, K, N, 2)
    return offsets.permute(0, 1, 3, 2).flatten(1, 2)


class QuadCNN(nn.Module):
    def __init__(self, k: int = K_NEIGHBOURS, widths=STAGE_WIDTHS, dropout: float = 0.5,
                 dynamic: bool = False, octaves: int = 0, global_width: int = GLOBAL_WIDTH,
                 head=(256, 256, 128), mean_pool: bool = False, keypoints: int = 0,
                 inputs: int = 4):
        super().__init__()
        self.k = k
        self.inputs = inputs
        self.dynamic = dynamic
        self.octaves = octaves
        self.edge = nn.ModuleList()
        self.point = nn.ModuleList()
        cin = inputs + 2 + 4 * octaves
        for w in widths:
            self.edge.append(EdgeConv(cin, w))
            self.point.append(_pointwise(cin, w))
            cin = 2 * w
        local = 2 * sum(widths)
        self.mean_pool = mean_pool
        self.to_global = _pointwise(local, global_width)
        self.keypoints = keypoints
        if keypoints:
            self.to_keypoints = nn.Conv1d(local, keypoints, 1)
        h1, h2, h3 = head
        self.head = nn.Sequential(
            nn.Conv1d(local + global_width + 2 * keypoints, h1, 1, bias=False),
            nn.BatchNorm1d(h1), nn.ReLU(),
            nn.Dropout(dropout),
            nn.Conv1d(h1, h2, 1, bias=False), nn.BatchNorm1d(h2), nn.ReLU(),
            nn.Dropout(dropout),
            nn.Conv1d(h2, h3, 1, bias=False), nn.BatchNorm1d(h3), nn.ReLU(),
            nn.Conv1d(h3, 2, 1))

    def forward(self, x: torch.Tensor, idx: torch.Tensor | None = None) -> torch.Tensor:
        """(B, N, inputs) points -> (B, N, 2) logits."""
        if idx is None:
            with torch.no_grad():
                idx = knn(x[..., :2], self.k)
        h = torch.cat([with_quartic(x), fourier_features(x[..., :2], self.octaves)],
                      dim=-1).transpose(1, 2)
        stages = []
        for i, (edge, point) in enumerate(zip(self.edge, self.point)):
            if self.dynamic and i > 0:
                with torch.no_grad():
                    idx = knn(h.transpose(1, 2), self.k)
            h = torch.cat([edge(h, idx), point(h)], dim=1)
            stages.append(h)
        local = torch.cat(stages, dim=1)
        features = self.to_global(local)
        pooled = features.max(dim=-1, keepdim=True).values
        if self.mean_pool:  # half the channels averaged: a gradient for every point
            half = features.shape[1] // 2
            pooled = torch.cat([pooled[:, :half], features[:, half:].mean(-1, keepdim=True)],
                               dim=1)
        parts = [local, pooled.expand(-1, -1, local.shape[-1])]
        if self.keypoints:
            parts.append(keypoint_offsets(self.to_keypoints(local), x[..., :2]))
        joined = torch.cat(parts, dim=1)
        return self.head(joined).transpose(1, 2)


class Probabilities(nn.Module):
    """What is exported to ONNX: the network with its sigmoid."""

    def __init__(self, net: QuadCNN):
        super().__init__()
        self.net = net

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return torch.sigmoid(self.net(x))
