"""``mbdsim cache info`` and ``mbdsim cache clear``: the on-disk cache of the compiled kernels.

Commands::

    mbdsim cache info
    mbdsim cache clear [--stale]

The cache (mbdsim._jitcache, mbdsim._cachedir) holds one directory per version of the kernel sources
under $NUMBA_CACHE_DIR or ~/.cache/mbdsim/numba; it is keyed on the kernels' content and the machine,
not on where mbdsim is installed, so clones and virtual environments share it. Exit status 0.
"""
from __future__ import annotations

import typer

cache_app = typer.Typer(help="The on-disk cache of the compiled kernels: info, clear.", no_args_is_help=True,
                        rich_markup_mode=None)


@cache_app.command("info")
def info_cmd() -> None:
    """Print where the compiled kernels are cached, which kernel version this mbdsim uses, how many
    kernels and bytes each cached version holds (a version not current is left by another mbdsim), and
    whether the package's shipped kernels serve this numba and Python.

    Example: mbdsim cache info"""
    from mbdsim import _cachedir
    from mbdsim._jitcache import base_dir
    vs = _cachedir.versions()
    typer.echo(f"cache directory: {base_dir()}")
    for v in vs:
        tag = "current" if v.current else "stale  "
        state = f"{v.kernels} kernels, {_cachedir.human(v.size)}" if v.kernels else "empty (compiles on first use)"
        typer.echo(f"  {tag} {v.digest}  {state}")
    from mbdsim import _jitcache, _kernelpack
    name = _kernelpack.pack_name(_jitcache._digest())
    shipped = sorted(p.name for p in _kernelpack.PACK_DIR.glob("*.tar.xz"))
    if name in shipped and _jitcache.PORTABLE:
        typer.echo(f"shipped kernels: {name} (unpacked into the current version on first use)")
    elif name in shipped:
        typer.echo(f"shipped kernels: {name}, not used: numba compiles for this machine's CPU "
                   "(MBDSIM_CPU=host or NUMBA_CPU_NAME set)")
    else:
        typer.echo(f"shipped kernels: {', '.join(shipped) or 'none'}; none for these kernel sources, numba and "
                   f"Python ({name}): kernels compile on first use")
    stale = [v for v in vs if not v.current]
    if stale:
        typer.echo(f"{len(stale)} stale version(s), {_cachedir.human(sum(v.size for v in stale))}: "
                   "'mbdsim cache clear --stale' removes them")


@cache_app.command("clear")
def clear_cmd(
    stale: bool = typer.Option(False, "--stale", help="Remove only the versions this mbdsim does not use."),
) -> None:
    """Remove the cached compiled kernels (all versions, or with --stale those of other mbdsim versions);
    the next analysis compiles again what it uses.

    Example: mbdsim cache clear --stale"""
    from mbdsim import _cachedir
    removed = _cachedir.clear(stale_only=stale)
    freed = sum(v.size for v in removed)
    typer.echo(f"removed {len(removed)} cached version(s), {_cachedir.human(freed)}")


def register(app: typer.Typer) -> None:
    """Add the ``cache`` command group to the mbdsim Typer app."""
    app.add_typer(cache_app, name="cache")
