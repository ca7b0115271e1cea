"""CasADi functions compiled to machine code on first use and cached on disk.

CasADi evaluates an SX function in a virtual machine, one instruction at a time. The planner's small
per-solve functions (objective, gradient, per-step reward curvature) run several times faster as C, and
compiling each takes seconds, so the package compiles them itself the first time a model is used and keeps
the shared library in a cache folder. Nothing binary is shipped.

The cache key is a SHA-256 of the generated C source (which holds every model constant), the compiler
command and the CasADi version, so a changed model, a changed formulation or a new CasADi builds a new
library; stale files are simply never looked up again. A library filed under a tag (the model's parameters) is
found again without generating its source, keyed on the tag and the source fingerprint: the source of the
modules the compiled functions are built from (:func:`compiling_modules` and what they import), so editing any other
module keeps the cache. The folder is ``$COMANIP_CACHE_DIR`` if set, else
``$XDG_CACHE_HOME/comanip`` or ``~/.cache/comanip``. Without a working C compiler (``$CC``, default
``gcc``) the uncompiled function is returned with a warning: same numbers, slower. Each compile shows a
progress line with its elapsed time (:mod:`comanip.progress`).

:func:`compile_in_background` builds one in a daemon thread while the caller goes on with the uncompiled
function (CasADi's virtual machine evaluates it meanwhile; compiled and uncompiled give identical numbers).
Background builds run one at a time, a build whose owner has been garbage-collected before it started is skipped,
and a compiler still running when Python exits is stopped and its scratch folder removed.
"""

from __future__ import annotations

import hashlib
import os
import shlex
import shutil
import subprocess
import tempfile
import threading
import warnings
import weakref
from concurrent.futures import Future
from importlib import metadata
from pathlib import Path
from typing import Callable

import casadi as ca

from comanip.caching.module_imports import PACKAGE, import_closure, module_files, names_imported_from
from comanip.caching.process_caches import PROCESS_CACHES, memoised
from comanip.progress import elapsed

COMPILE_FLAGS = ("-O1", "-fPIC", "-shared")
"""Flags for the C compiler: -O1, because the generated code is straight-line SX instructions, which -O2 does not
make faster but takes longer to compile."""
PROCESSOR_FLAGS = ("-O2", "-march=native", "-fPIC", "-shared")
"""Flags for a function built ``for_this_processor``: this processor's own instructions, and -O2, which fuses
multiplications and additions into its fused multiply-adds. Large functions (an arm's gradient) run markedly faster
(docs/results/speed.md); the build takes about three times longer, the numbers are rounded differently from
CasADi's virtual machine (a fused multiply-add rounds once), and the library runs only on processors like this one,
so the processor is part of its cache key."""


def cache_dir() -> Path:
    """The folder holding compiled libraries (created on demand)."""
    if os.environ.get("COMANIP_CACHE_DIR"):
        return Path(os.environ["COMANIP_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "comanip"


def compiled(function: ca.Function, tag: str | None = None, for_this_processor: bool = False) -> ca.Function:
    """``function`` as compiled C, built on first use and loaded from the disk cache afterwards.

    The returned function has the same name, inputs and outputs. It has no derivatives: compile the
    derivative functions you need (e.g. ``function.reverse(1)``) separately.

    ``tag``: a string that, with this package's source code, determines the function (e.g. the model's
    parameters); the library is then also filed under it, so :func:`cached_compiled` finds it later without
    generating the C source (itself costly for large functions).

    ``for_this_processor``: build with :data:`PROCESSOR_FLAGS` (faster, rounded differently from the uncompiled
    function) where the compiler names the processor it builds for; elsewhere, or if that build fails, with
    :data:`COMPILE_FLAGS`.
    """
    name = function.name()
    generator = ca.CodeGenerator(name, {"with_header": False})
    generator.add(function)
    source = generator.dump()
    compiler, flags = _compiler(), _flags(for_this_processor)
    key = hashlib.sha256("\n".join([source, " ".join(compiler + flags), ca.__version__]).encode()).hexdigest()[:20]
    library = cache_dir() / f"{name}_{key}.so"
    if not library.exists():
        try:
            with elapsed(f"compiling {name} to C (first use of this model; cached in {cache_dir()})"):
                _build(source, compiler, flags, library)
        except (OSError, subprocess.CalledProcessError) as error:
            if for_this_processor:
                return compiled(function, tag)
            detail = getattr(error, "stderr", "") or error
            warnings.warn(f"could not compile {name} with {' '.join(compiler)} ({str(detail)[:300]}); "
                          "using CasADi's virtual machine instead (same results, slower)", RuntimeWarning, stacklevel=2)
            return function
    if tag is not None:
        _file_under_tag(name, tag, flags, library)
    return ca.external(name, str(library))


def cached_compiled(name: str, tag: str, for_this_processor: bool = False) -> ca.Function | None:
    """The compiled function ``name`` filed under ``tag`` by an earlier :func:`compiled` (with the same
    ``for_this_processor``) with this package's source code, this CasADi and this compiler; None if there is none."""
    index = cache_dir() / f"{name}_{_tag_key(tag, _flags(for_this_processor))}.tag"
    try:
        library = cache_dir() / index.read_text().strip()
    except OSError:
        return None
    return ca.external(name, str(library)) if library.exists() else None


def _file_under_tag(name: str, tag: str, flags: list[str], library: Path) -> None:
    """Write the index file naming ``library`` for (name, tag, flags), atomically."""
    index = cache_dir() / f"{name}_{_tag_key(tag, flags)}.tag"
    scratch = index.with_suffix(f".{os.getpid()}.{threading.get_ident()}")
    scratch.write_text(library.name)
    os.replace(scratch, index)


def compiled_or_cached(function: ca.Function, tag: str, for_this_processor: bool = False) -> ca.Function:
    """:func:`cached_compiled` if ``function`` was compiled under ``tag`` before, else :func:`compiled`."""
    return cached_compiled(function.name(), tag, for_this_processor) or compiled(function, tag, for_this_processor)


def _tag_key(tag: str, flags: list[str]) -> str:
    """Key of a tag: with the package's source, the versions of the libraries that build the functions and
    the compiler and its flags, the function is fixed."""
    parts = [tag, _source_fingerprint(), " ".join(_compiler() + flags)]
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()[:20]


def _flags(for_this_processor: bool) -> list[str]:
    """The compiler flags of a build; a build for this processor ends with a definition naming the instructions the
    compiler chooses for it (:func:`_processor`), so that the cache keys tell processors apart."""
    processor = _processor() if for_this_processor else None
    if processor is None:
        return list(COMPILE_FLAGS)
    return [*PROCESSOR_FLAGS, f"-DCOMANIP_PROCESSOR={processor}"]


@memoised(maxsize=1)
def _processor() -> str | None:
    """A fingerprint of what ``-march=native`` means to the compiler here: the processor it names and the instruction
    sets it enables (a virtual machine may hide some of a processor's); None where the compiler does not say (then
    no build is made for this processor alone)."""
    try:
        shown = subprocess.run([*_compiler(), "-march=native", "-Q", "--help=target"], capture_output=True, text=True,
                               timeout=60).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    targets = sorted(" ".join(line.split()) for line in shown.splitlines() if line.strip().startswith("-m"))
    if not any(target.startswith("-march= ") and target != "-march= native" for target in targets):
        return None
    return hashlib.sha256("\n".join(targets).encode()).hexdigest()[:16]


FUNCTION_SOURCES = ("casadi", "adam-robotics", "example-robot-data")
"""Distributions whose versions, with comanip's own source, determine a compiled function (the Panda's
dynamics come from adam and the URDF of example-robot-data)."""


BUILDERS = ("compiled", "compiled_or_cached", "cached_compiled", "compile_in_background")
"""The functions of this module that hand CasADi functions to the compiler (or look up their builds)."""


def compiling_modules(package: Path = PACKAGE) -> set[str]:
    """The modules of ``package`` that import one of :data:`BUILDERS`: those the compiled functions are built in."""
    return {name for name, path in module_files(package).items()
            if __name__ in path.read_text() and set(BUILDERS) & names_imported_from(path, __name__)}


@memoised(maxsize=4)
def _source_fingerprint(package: Path = PACKAGE) -> str:
    """SHA-256 of the source of :func:`compiling_modules` and every module they import in ``package``, and of the
    versions of :data:`FUNCTION_SOURCES` (a changed formulation or library is a changed fingerprint): editing a
    module they do not import (a plot, a command, a scenario, the people model) keeps the cache."""
    files = module_files(package)
    digest = hashlib.sha256()
    for module in sorted(import_closure(compiling_modules(package), package)):
        digest.update(module.encode())
        digest.update(files[module].read_bytes())
    for distribution in FUNCTION_SOURCES:
        try:
            digest.update(f"{distribution}=={metadata.version(distribution)}".encode())
        except metadata.PackageNotFoundError:
            digest.update(f"{distribution} absent".encode())
    return digest.hexdigest()


def _compiler() -> list[str]:
    return shlex.split(os.environ.get("CC", "gcc"))


class Compilers:
    """The compiler processes of this Python process: background builds run one at a time (each compiler takes a
    core), and compilers still running at exit are stopped and their scratch folders removed (a background
    build's daemon thread dies with Python and would leave them behind)."""

    def __init__(self):
        self.turn = threading.Lock()
        """Held by the background build in progress."""
        self.running: dict[subprocess.Popen, str] = {}
        """Compiler processes in progress and their scratch folders."""

    def in_background(self, owner: object, functions_of: Callable[[object], list[ca.Function]],
                      tag: str | None = None) -> Future:
        """Start compiling ``functions_of(owner)`` in a daemon thread; the future's result is the list of compiled
        functions (:func:`compiled` of each, in order, filed under ``tag``).

        Only a weak reference to ``owner`` is kept: if it is garbage-collected before its turn comes (builds run
        one at a time), the build is skipped and the future holds None. A failed build (no compiler) gives the
        uncompiled function with a warning, as :func:`compiled` does.
        """
        future: Future = Future()
        reference = weakref.ref(owner)

        def build():
            with self.turn:
                try:
                    owner = reference()
                    future.set_result(None if owner is None else [compiled(f, tag) for f in functions_of(owner)])
                except BaseException as error:  # handed to the caller through the future
                    future.set_exception(error)

        threading.Thread(target=build, name="comanip-compile", daemon=True).start()
        return future

    def stop_running(self) -> None:
        """Stop the compilers still running and remove their scratch folders."""
        _stop(self.running)


def _stop(running: dict[subprocess.Popen, str]) -> None:
    """Stop the compiler processes of ``running`` and remove their scratch folders."""
    for process, scratch in list(running.items()):
        process.kill()
        process.wait()
        shutil.rmtree(scratch, ignore_errors=True)


def _started_compilers() -> Compilers:
    """Compilers whose processes are stopped when they are dropped or, at the latest, when Python exits."""
    made = Compilers()
    weakref.finalize(made, _stop, made.running)
    return made


def compilers() -> Compilers:
    """This process's compilers (:data:`comanip.caching.process_caches.PROCESS_CACHES`; stopped at exit)."""
    return PROCESS_CACHES.get("compilers", _started_compilers)


def compile_in_background(owner: object, functions_of: Callable[[object], list[ca.Function]], tag: str | None = None) -> Future:
    """:meth:`Compilers.in_background` of this process's compilers."""
    return compilers().in_background(owner, functions_of, tag)


def _build(source: str, compiler: list[str], flags: list[str], library: Path) -> None:
    """Compile C source into ``library`` with ``flags``, atomically (a concurrent build of the same key is harmless)."""
    library.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=library.parent) as scratch:
        c_file = Path(scratch) / f"{library.stem}.c"
        c_file.write_text(source)
        built = Path(scratch) / library.name
        process = subprocess.Popen([*compiler, *flags, str(c_file), "-o", str(built), "-lm"],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        compilers().running[process] = scratch
        try:
            output, errors = process.communicate()
        finally:
            compilers().running.pop(process, None)
        if process.returncode != 0:
            raise subprocess.CalledProcessError(process.returncode, process.args, output, errors)
        os.replace(built, library)
