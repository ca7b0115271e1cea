"""The benchmarks behind the speed results page; their problem sets (``benchmarks.workspace``, ``benchmarks.cold_quality``,
``benchmarks.franka_rest``) are imported by the studies as modules of this package."""
