"""Attitude algorithms: the algorithm model and registry, coning-correction sets, update
structures, rate-input and quaternion algorithms, cone-angle kinematics, streaming, the
arbitrary-precision path, and the compiled kernels with their plain-Python twin."""
