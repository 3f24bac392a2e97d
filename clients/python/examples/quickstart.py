import sys

import driftlab

server = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
job = sys.argv[2] if len(sys.argv) > 2 else "examples/car_drive.json"
with driftlab.connect(server, wait_s=30) as client:
    result = client.run(job, runs=50, progress=True)  # NumPy arrays: epochs x components
h = driftlab.component_index("horizontal_position_m")
print(f"final horizontal sigma: {result.std[-1, h]!r} m at t = {result.t_s[-1]} s")
