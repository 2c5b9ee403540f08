"""Applications behind the command line: run a log, compare algorithms, sweep scenarios,
benchmark throughput, run and benchmark the AHRS."""
