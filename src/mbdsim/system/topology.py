"""Spanning tree of a system's constraint rows, for the O(N) solve of the equations of motion.

Frames (bodies) are the nodes and joints the edges. A breadth-first search from ground (then from any
body not reached, as a floating root) picks one joint per body, its *tree joint*; the body's
independent rows of that joint and of the motions driving it form the body's *block*. Every other row
(loop-closing joints, motions on them) is a *loop row*, coupled through a small dense Schur complement.
See docs/theory.md section "O(N) equations of motion".
"""
from __future__ import annotations

from collections import deque
from itertools import accumulate
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Topology:
    """Tree blocks and loop rows over frames 0..nf-1 (0 = ground); arrays only, read by numba kernels.

    order: frames in breadth-first order (roots first, ground excluded); pblk[f]: the block whose child is
    frame f (-1 for a root); blk_child / blk_parent: child and parent frame of each block (parent 0 =
    ground); blk_ptr, blk_rows: CSR list of each block's global row indices (at most 6 per block);
    ch_ptr, ch_blk: CSR list of the blocks whose parent is frame f; loop_rows: the other rows."""

    order: np.ndarray
    pblk: np.ndarray
    blk_child: np.ndarray
    blk_parent: np.ndarray
    blk_ptr: np.ndarray
    blk_rows: np.ndarray
    ch_ptr: np.ndarray
    ch_blk: np.ndarray
    loop_rows: np.ndarray


def _csr(lists):
    ptr = np.fromiter(accumulate((len(x) for x in lists), initial=0), dtype=np.int64, count=len(lists) + 1)
    flat = np.array([i for x in lists for i in x], dtype=np.int64)
    return ptr, flat


def spanning_tree(nf: int, edges: list[tuple[str, int, int]], rows_of: dict[str, list[int]]) -> Topology:
    """Topology from joints `edges` (name, frame_i, frame_j) and each joint's independent rows (its own and
    its motions'). A joint whose block would exceed 6 rows goes to the loop rows."""
    adj: dict[int, list[tuple[str, int]]] = {f: [] for f in range(nf)}
    for name, fi, fj in edges:
        adj[fi].append((name, fj))
        adj[fj].append((name, fi))
    parent_edge: dict[int, tuple[str, int]] = {}
    seen, order = set(), []
    tree_names: set[str] = set()
    for root in range(nf):
        if root in seen:
            continue
        seen.add(root)
        if root != 0:
            order.append(root)
        queue = deque([root])
        while queue:
            f = queue.popleft()
            for name, g in adj[f]:
                if g in seen or name in tree_names or len(rows_of.get(name, ())) > 6:
                    continue
                seen.add(g)
                tree_names.add(name)
                parent_edge[g] = (name, f)
                order.append(g)
                queue.append(g)
    pblk = -np.ones(nf, dtype=np.int64)
    blk_child, blk_parent, blk_rows, children = [], [], [], [[] for _ in range(nf)]
    for f in order:
        if f in parent_edge:
            name, p = parent_edge[f]
            pblk[f] = len(blk_child)
            children[p].append(len(blk_child))
            blk_child.append(f)
            blk_parent.append(p)
            blk_rows.append(sorted(rows_of.get(name, [])))
    loop = sorted(r for name, rs in rows_of.items() if name not in tree_names for r in rs)
    blk_ptr, blk_flat = _csr(blk_rows)
    ch_ptr, ch_flat = _csr(children)
    return Topology(np.array(order, dtype=np.int64), pblk, np.array(blk_child, dtype=np.int64),
                    np.array(blk_parent, dtype=np.int64), blk_ptr, blk_flat, ch_ptr, ch_flat,
                    np.array(loop, dtype=np.int64))


def system_topology(sys, rows) -> Topology:
    """Topology of a System for its independent rows `rows` (joints as edges; motions join their joint).
    The joint graph, each row's joint and the topology of all rows are kept in sys.derived, and so are
    the topologies of the last few row sets asked for (functions of the System alone).  When no joint
    has more than 6 rows the tree does not depend on the rows (spanning_tree), so the topology of a
    strictly increasing subset of the rows is that of all rows with the other rows left out."""
    rows = np.asarray(rows, dtype=int)
    kept = sys.derived.setdefault("topologies", {})
    key = rows.tobytes()
    topo = kept.get(key)
    if topo is None:
        if len(kept) >= 4:
            kept.clear()
        full = _full_topology(sys)
        if full is not None and _increasing_subset(rows, sys.nc):
            topo = _restricted(full, rows, sys.nc)
        else:
            topo = _system_topology(sys, rows)
        kept[key] = topo
    return topo


_SHARED: dict = {}    # structure_key -> {name: value}: functions of the structure alone (see shared)
_SHARED_MAX = 16


def structure_key(sys) -> tuple:
    """What the joint graph (joint kinds included), the rows' owners and the velocity layout of a System
    are made of (kept in sys.derived): Systems with equal keys have the same topologies and tree plans."""
    key = sys.derived.get("structure_key")
    if key is None:
        model = sys.model
        key = sys.derived["structure_key"] = (
            sys.nbody, sys.nc, tuple(sys.row_owner), tuple((m.name, m.joint.name) for m in model.motions.values()),
            tuple((j.name, j.kind, sys.fid[j.body_i], sys.fid[j.body_j]) for j in model.joints.values()),
            sys.frame_v_adr.tobytes(), sys.frame_rigid.tobytes())
    return key


def shared(sys, name: str, make):
    """make(sys), a function of structure_key(sys) alone, kept in sys.derived and shared by the Systems
    of the same structure (the variants of a parameter study: computed once, not once per variant).
    Its arrays are shared too: callers must not change them, nor hand them out."""
    if name in sys.derived:
        return sys.derived[name]
    key = structure_key(sys)
    entry = _SHARED.get(key)
    if entry is None:
        if len(_SHARED) >= _SHARED_MAX:
            _SHARED.pop(next(iter(_SHARED)))   # the oldest structure
        entry = _SHARED[key] = {}
    if name not in entry:
        entry[name] = make(sys)
    value = sys.derived[name] = entry[name]
    return value


def _full_topology(sys) -> Topology | None:
    """Topology of all sys.nc rows when no joint has more than 6 of them, else None (shared)."""
    return shared(sys, "topology_all", _make_full_topology)


def _make_full_topology(sys) -> Topology | None:
    edges, row_joint = _joint_graph(sys)
    known = {e[0] for e in edges}
    count: dict = {}
    for name in row_joint:
        count[name] = count.get(name, 0) + 1
    small = all(n <= 6 for name, n in count.items() if name in known)
    return _system_topology(sys, np.arange(sys.nc)) if small else None


def _increasing_subset(rows, nc) -> bool:
    return len(rows) == 0 or (rows[0] >= 0 and rows[-1] < nc and bool(np.all(rows[1:] > rows[:-1])))


def _restricted(full: Topology, rows, nc) -> Topology:
    """The topology of all rows with those not in `rows` removed from the blocks and the loop rows (new
    arrays: `full` is shared)."""
    if len(rows) == nc:
        return Topology(*(x.copy() for x in (full.order, full.pblk, full.blk_child, full.blk_parent,
                                              full.blk_ptr, full.blk_rows, full.ch_ptr, full.ch_blk,
                                              full.loop_rows)))
    keep = np.zeros(nc, dtype=bool)
    keep[rows] = True
    inblk = keep[full.blk_rows]
    counts = np.add.reduceat(inblk.astype(np.int64), full.blk_ptr[:-1]) if len(full.blk_rows) else \
        np.zeros(len(full.blk_child), dtype=np.int64)
    counts[full.blk_ptr[:-1] == full.blk_ptr[1:]] = 0   # reduceat of an empty block reads the next entry
    ptr = np.zeros(len(full.blk_child) + 1, dtype=np.int64)
    ptr[1:] = np.cumsum(counts)
    return Topology(full.order.copy(), full.pblk.copy(), full.blk_child.copy(), full.blk_parent.copy(), ptr,
                    full.blk_rows[inblk], full.ch_ptr.copy(), full.ch_blk.copy(), full.loop_rows[keep[full.loop_rows]])


def _joint_graph(sys):
    """(edges (name, frame_i, frame_j) of the joints between two frames, each row's joint or owner name)."""
    return shared(sys, "joint_graph", _make_joint_graph)


def _make_joint_graph(sys):
    model = sys.model
    joint_of = {m.name: m.joint.name for m in model.motions.values()}
    edges = [(j.name, sys.fid[j.body_i], sys.fid[j.body_j]) for j in model.joints.values()
             if sys.fid[j.body_i] != sys.fid[j.body_j]]
    return edges, [joint_of.get(o, o) for o in sys.row_owner]


def _system_topology(sys, rows) -> Topology:
    edges, row_joint = _joint_graph(sys)
    rows_of: dict[str, list[int]] = {}
    for r in rows.tolist():
        rows_of.setdefault(row_joint[r], []).append(r)
    known = {e[0] for e in edges}
    rows_of_edges = {k: v for k, v in rows_of.items() if k in known}
    topo = spanning_tree(sys.nbody + 1, edges, rows_of_edges)
    extra = [r for k, v in rows_of.items() if k not in known for r in v]   # rows of non-joint owners
    if extra:
        loop = np.array(sorted(list(topo.loop_rows) + extra), dtype=np.int64)
        topo = Topology(**{**topo.__dict__, "loop_rows": loop})
    return topo
