"""What is costly to build, built once: CasADi functions compiled to C and cached on disk (in the foreground
or in a background thread), their zero-copy calls from NumPy, and objects kept by their model's parameters (in
a process, or in each Dask worker)."""
