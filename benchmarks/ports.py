"""Time per state of MuJoCo's ports against MuJoCo C's per-state call, on this machine's
device (JAX's default device; Warp's from ``DYNCHECK_DEVICE``), compile time apart.

    python benchmarks/ports.py [--out reports/benchmark-ports.md] [--batches 256 4096 65536]

For each case: MuJoCo C's plainest loop (``mj_forward`` + ``mj_fullM`` + ``mj_inverse`` per
state); each installed port's batched path (every quantity dyncheck compares) at each batch
size — its first call (tracing and compilation included; JAX's persistent cache is off here,
so the number is the cold cost) and the median of five calls after it. Writes a Markdown table
(to stdout and ``--out``, by default ``reports/benchmark-ports.md``, linked from
``reports/benchmark.md``'s reader in the README); on a GPU machine write it elsewhere
(``--out /tmp/ports-gpu.md``): the device is named in the output.
"""

from __future__ import annotations

import argparse
import platform
import statistics
import time
from pathlib import Path


def _states(case, n: int):
    from dyncheck import coordinates as co
    from dyncheck.implementations import make_implementation

    s = case.sample_states(n)
    m = make_implementation("mujoco", case).map
    return (
        m.to_engine(s.q),
        co.velocity_to_engine(m, s.q, s.v),
        co.force_to_engine(m, s.q, s.tau),
        co.acceleration_to_engine(m, s.q, s.v, s.a),
    )


def _raw_c(adapter, qe, ve, te, ae) -> float:
    """Seconds per state of the loop ``dyncheck bench`` times for MuJoCo C (its loader's
    per-state calls, ``raw_calls``)."""
    loop = adapter.raw_calls(qe, ve, te, ae)
    t0 = time.perf_counter()
    loop()
    return (time.perf_counter() - t0) / len(qe)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("reports/benchmark-ports.md"))
    parser.add_argument("--batches", type=int, nargs="+", default=[256, 4096, 65536])
    parser.add_argument("--case", action="append", default=[])
    args = parser.parse_args()

    import jax

    jax.config.update("jax_enable_compilation_cache", False)
    from dyncheck.adapters import ENGINE_PORTS
    from dyncheck.adapters.installed import ENGINES, engine_version, get_engine
    from dyncheck.case_engine import CaseEngine
    from dyncheck.cases import get_case

    cases = args.case or ["compound_pendulum", "rigid_body_free"]
    device = jax.devices()[0]
    lines = [
        f"Device: JAX {device.platform} ({device.device_kind}); host {platform.machine()}; "
        f"ports: {', '.join(engine_version(p) for p in ENGINE_PORTS if p in ENGINES)}",
        "",
        "| case | implementation | batch | first call (s) | µs per state | × MuJoCo C |",
        "|---|---|---|---|---|---|",
    ]
    for name in cases:
        case = get_case(name)
        mb = case.multibody()
        c = CaseEngine("mujoco", mb, loader=get_engine("mujoco"))
        raw = _raw_c(c, *_states(case, 2000))
        lines.append(f"| {name} | mujoco (C, per state) | 1 | – | {1e6 * raw:.3g} | 1 |")
        for port in ENGINE_PORTS:
            if port not in ENGINES:
                continue
            for batch in args.batches if port != "mujoco-warp" else [256]:
                adapter = CaseEngine(port, mb, loader=get_engine(port))
                if port != "mujoco-warp":
                    adapter.engine.port.chunk = batch  # the port's states per batched call
                x = _states(case, batch)
                t0 = time.perf_counter()
                adapter.evaluate_all(*x)
                first = time.perf_counter() - t0
                times = []
                for _ in range(5):
                    t0 = time.perf_counter()
                    adapter.evaluate_all(*x)
                    times.append(time.perf_counter() - t0)
                per = statistics.median(times) / batch
                lines.append(
                    f"| {name} | {port} | {batch} | {first:.3g} | {1e6 * per:.3g} "
                    f"| {per / raw:.3g} |"
                )
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out is not None:
        args.out.write_text(text)


if __name__ == "__main__":
    main()
