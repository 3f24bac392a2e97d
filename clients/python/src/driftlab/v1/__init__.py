"""The driftlab.v1 protobuf and gRPC modules, generated from proto/driftlab/v1/*.proto when the
package is built (setup.py) or by the CMake build into <build>/python/driftlab/v1/."""
