#!/usr/bin/python3
"""The scipy side of the modal scale benchmark (docs/benchmarks_modal.md).

Reads K.mtx and M.mtx written by `bench_modal_scale SIZE --export DIR`, solves
K phi = lambda M phi for the k lowest modes with
scipy.sparse.linalg.eigsh(K, k, M=M, sigma=sigma, which='LM') (shift-invert about the same
sigma as jointid, below the first eigenvalue), and prints one JSON line: solve time (file
reading excluded), peak memory, eigenvalues and, given jointid's JSON line, the largest
relative difference of the eigenvalues.

  scipy_modal.py DIR --sigma S [--k 20] [--jointid JOINTID.json] [--lu default|symmetric]

--lu default: eigsh as a user calls it (scipy factorises K - sigma M with splu, COLAMD
ordering, partial pivoting). --lu symmetric: the same eigsh call with OPinv = a SuperLU
factorisation in symmetric mode (MMD on A^T + A, diagonal pivots), the best scipy offers
without extra packages.

Run with Debian's /usr/bin/python3 (python3-scipy).
"""
import argparse
import json
import resource
import sys
import time

import numpy as np
import scipy
import scipy.io
import scipy.sparse.linalg as sla


def rss_mib(field):
    """VmHWM (peak) or VmRSS (current) of this process in MiB, from /proc/self/status."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 1024.0
    return -1.0


def reset_peak_rss():
    """Resets the kernel's peak-RSS mark, so the next VmHWM is the peak of what follows."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("dir", help="folder with K.mtx and M.mtx")
    parser.add_argument("--sigma", type=float, required=True,
                        help="shift, below the lowest eigenvalue (jointid: -(2 pi 1 Hz)^2)")
    parser.add_argument("--k", type=int, default=20, help="number of modes")
    parser.add_argument("--jointid", help="jointid's JSON line (bench_modal_scale output)")
    parser.add_argument("--lu", choices=["default", "symmetric"], default="default")
    args = parser.parse_args()

    result = {"scipy": scipy.__version__, "numpy": np.__version__, "lu": args.lu,
              "sigma": args.sigma, "k": args.k}
    start = time.perf_counter()
    K = scipy.io.mmread(f"{args.dir}/K.mtx").tocsc()
    M = scipy.io.mmread(f"{args.dir}/M.mtx").tocsc()
    result["read_s"] = time.perf_counter() - start
    result["dofs"] = K.shape[0]
    result["nnz_K"] = int(K.nnz)
    result["peak_rss_read_mib"] = rss_mib("VmHWM")
    result["rss_before_solve_mib"] = rss_mib("VmRSS")
    result["peak_reset"] = reset_peak_rss()

    start = time.perf_counter()
    if args.lu == "default":
        lam, phi = sla.eigsh(K, k=args.k, M=M, sigma=args.sigma, which="LM")
    else:
        lu = sla.splu((K - args.sigma * M).tocsc(), permc_spec="MMD_AT_PLUS_A",
                      diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        opinv = sla.LinearOperator(K.shape, matvec=lu.solve, dtype=K.dtype)
        lam, phi = sla.eigsh(K, k=args.k, M=M, sigma=args.sigma, which="LM", OPinv=opinv)
    result["eigsh_s"] = time.perf_counter() - start
    result["peak_rss_solve_mib"] = rss_mib("VmHWM")
    # ru_maxrss is reset together with VmHWM, so it is the solve's peak too; the whole run's
    # peak is the larger of this and the reading peak.
    result["ru_maxrss_mib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    result["peak_rss_total_mib"] = max(result["peak_rss_read_mib"], result["peak_rss_solve_mib"])

    order = np.argsort(lam)
    lam, phi = lam[order], phi[:, order]
    KPhi, MPhi = K @ phi, M @ phi
    result["residual"] = float(np.linalg.norm(KPhi - MPhi * lam) / np.linalg.norm(KPhi))
    result["orthonormality"] = float(np.abs(phi.T @ MPhi - np.eye(args.k)).max())
    result["eigenvalues"] = [float(x) for x in lam]
    if args.jointid:
        with open(args.jointid) as f:
            ours = np.array(json.loads(f.readline())["eigenvalues"])
        if ours.shape != lam.shape:
            sys.exit(f"scipy_modal.py: {args.jointid} has {ours.size} eigenvalues, "
                     f"scipy found {lam.size}")
        result["max_rel_diff"] = float(np.max(np.abs(ours - lam) / np.abs(lam)))
    print(json.dumps(result))


if __name__ == "__main__":
    main()
