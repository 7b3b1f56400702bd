"""Bounding-volume hierarchy of a triangle mesh (issue 30), built once at pack time for solvers.fastmesh.

A binary tree of axis-aligned boxes in the mesh's own axes [m]: each node splits its triangles at the
median of their centroids along the axis where the centroids spread most, down to LEAF triangles.
"""
from __future__ import annotations

import numpy as np

LEAF = 4   # triangles per leaf at most


def build(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(triangle order (m,), node boxes (nn, 6): lower and upper corner [m], node links (nn, 4): left and
    right child, or -1, -1 and the leaf's first position in the order and its count).  Node 0 is the root."""
    tv = np.asarray(vertices, float)[np.asarray(faces, np.int64)]
    lo_t, hi_t, cent = tv.min(axis=1), tv.max(axis=1), tv.mean(axis=1)
    boxes, links, order = [], [], []

    def node(idx):
        me = len(boxes)
        boxes.append(np.concatenate([lo_t[idx].min(axis=0), hi_t[idx].max(axis=0)]))
        links.append(None)
        if len(idx) <= LEAF:
            links[me] = (-1, -1, len(order), len(idx))
            order.extend(idx.tolist())
            return me
        c = cent[idx]
        ax = int(np.argmax(c.max(axis=0) - c.min(axis=0)))
        srt = idx[np.argsort(c[:, ax], kind="stable")]
        h = len(srt) // 2
        left = node(srt[:h])
        links[me] = (left, node(srt[h:]), 0, 0)
        return me

    node(np.arange(len(tv)))
    return np.array(order, np.int64), np.array(boxes, float).reshape(-1, 6), np.array(links, np.int64).reshape(-1, 4)
