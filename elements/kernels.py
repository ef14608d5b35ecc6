"""Shared numba kernels for 2-D line elements: local-to-global rotation of element matrices."""
import numpy as np
from numba import njit


@njit(cache=True)
def rotate_to_global(local, c, s, nodes, dofs_per_node):
    """Return ``Tᵀ k T`` for every element.

    ``local`` is ``(n_el, nd, nd)`` in local axes (x along the element); ``c, s`` are the
    direction cosines ``(n_el,)``; each node carries ``dofs_per_node`` dofs (2: ux, uy; 3: ux,
    uy, rz), whose first two rotate.
    """
    n_el, nd, _ = local.shape
    out = np.empty_like(local)
    t = np.zeros((nd, nd))
    for e in range(n_el):
        t[:, :] = 0.0
        for a in range(nodes):
            o = a * dofs_per_node
            t[o, o] = c[e]
            t[o, o + 1] = s[e]
            t[o + 1, o] = -s[e]
            t[o + 1, o + 1] = c[e]
            for d in range(2, dofs_per_node):
                t[o + d, o + d] = 1.0
        for i in range(nd):
            for j in range(nd):
                acc = 0.0
                for k in range(nd):
                    tki = t[k, i]
                    if tki == 0.0:
                        continue
                    for m in range(nd):
                        acc += tki * local[e, k, m] * t[m, j]
                out[e, i, j] = acc
    return out
