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


def swept(vertices: np.ndarray, faces: np.ndarray, boxes: np.ndarray, links: np.ndarray, depth: float) -> np.ndarray:
    """Node boxes (nn, 6: lower and upper corner [m]) grown to hold each of their triangles moved by up to depth
    [m] along its inward normal (-n, n by the right-hand rule): a point up to depth below a triangle lies in
    its leaf's swept box.  faces in the hierarchy's order (`build`'s order applied), links as `build` returns."""
    tv = np.asarray(vertices, float)[np.asarray(faces, np.int64)]
    n = np.cross(tv[:, 1] - tv[:, 0], tv[:, 2] - tv[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    lo, hi = tv.min(axis=1), tv.max(axis=1)
    lo, hi = np.minimum(lo, lo - depth * n), np.maximum(hi, hi - depth * n)
    out = np.array(boxes, float).reshape(-1, 6).copy()
    for nd in range(len(links) - 1, -1, -1):   # children come after their parent
        if links[nd, 0] < 0:
            s, c = links[nd, 2], links[nd, 3]
            out[nd] = np.concatenate([lo[s:s + c].min(axis=0), hi[s:s + c].max(axis=0)])
        else:
            a, b = out[links[nd, 0]], out[links[nd, 1]]
            out[nd] = np.concatenate([np.minimum(a[:3], b[:3]), np.maximum(a[3:], b[3:])])
    return out
