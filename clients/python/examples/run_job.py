#!/usr/bin/python3
"""Runs a driftlab job on a driftlab-server and plots its error envelopes.

    /usr/bin/python3 clients/python/examples/run_job.py --server HOST:PORT \\
      examples/car_drive.json --runs 20 --plot envelopes.png [--out result.json]

Submits the job (JSON job file), prints progress lines while the server runs it, prints the
final-epoch statistics, writes the result (--out) and the plot of mean +- 1 sigma per error
component over time (--plot). Exit status: 0 done, 2 the server rejected the job (its message
names the field), 1 any other failure (server unreachable, bad token, job failed).
"""

import argparse
import os
import sys

try:
    import driftlab
except ImportError as error:
    sys.exit(f"error: {error}; install the package (pip install --no-build-isolation "
             "./clients/python) or set PYTHONPATH=<build>/python")

import grpc
from driftlab.v1 import service_pb2
from google.protobuf import json_format


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("job", help="job file (JSON, protobuf JSON mapping)")
    parser.add_argument("--server", required=True, help="driftlab-server HOST:PORT")
    parser.add_argument("--token", default=None,
                        help="bearer token (default: environment DRIFTLAB_TOKEN)")
    parser.add_argument("--tls-ca", default=None, help="CA certificate (PEM) for TLS")
    parser.add_argument("--runs", type=int, default=None, help="override monte_carlo.runs")
    parser.add_argument("--seed", type=int, default=None, help="override monte_carlo.seed")
    parser.add_argument("--timeout", type=float, default=3600.0,
                        help="seconds to wait for the job (default 3600)")
    parser.add_argument("--plot", default=None, help="write the error-envelope plot here")
    parser.add_argument("--out", default=None, help="write the result JSON here")
    args = parser.parse_args()

    client = driftlab.connect(args.server, token=args.token, tls_ca=args.tls_ca)
    try:
        job_id = client.submit(args.job, runs=args.runs, seed=args.seed)
        print(f"submitted job {job_id} to {args.server}", file=sys.stderr)
        final = client.wait(job_id, timeout_s=args.timeout, progress=True)
        if final.state != service_pb2.SUCCEEDED:
            state = service_pb2.JobState.Name(final.state)
            print(f"error: job {job_id} {state}: {final.error}", file=sys.stderr)
            return 1
        result = client.result(job_id)
    except driftlab.DriftlabError as error:
        print(f"error: {error.details}" if error.code == grpc.StatusCode.INVALID_ARGUMENT
              else f"error: {error}", file=sys.stderr)
        return 2 if error.code == grpc.StatusCode.INVALID_ARGUMENT else 1
    except (OSError, ValueError, json_format.ParseError) as error:  # unreadable or bad job file
        print(f"error: {error}", file=sys.stderr)
        return 2
    finally:
        client.close()

    print("\n".join(driftlab.summary_lines(result)))
    if args.out:
        result.write(args.out)
        print(f"wrote {args.out}")
    if args.plot:
        driftlab.plot_envelopes(result, args.plot)
        print(f"wrote {args.plot}")
    return 0


if __name__ == "__main__":
    os.environ.setdefault("MPLBACKEND", "Agg")
    sys.exit(main())
