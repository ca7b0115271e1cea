"""Studies, one folder per question; run a script from the repository root as ``python -m studies.<question>.<script>``
(so that it imports the benchmarks' problem sets as ``benchmarks.<script>`` and shared helpers as ``studies.<module>``)."""
