"""The compiled loop of a force, looked up once per force.

Building a loop's specialised copy (:func:`orbits._kernels._jit.specialize`
and the bindings it is given) costs some 20 µs of Python even when the copy
is cached, which an adaptive run pays at every output: it enters the loop
once per output time.  :func:`loop_for` keeps what a factory returned for a
force, keyed as :func:`~orbits._kernels._jit.specialize` keys its copies (the
force's ``key`` names its kernels), so that the second call costs a
dictionary lookup.
"""

__all__ = ["loop_for"]

_LOOPS = {}


def loop_for(factory, force, *args, **options):
    """``factory(force, *args, **options)``, remembered per force kernel.

    Examples
    --------
    >>> from orbits._kernels import ias15, stepping
    >>> from orbits.integrators._loops import loop_for
    >>> force = stepping.gravity_force("small")
    >>> loop_for(ias15.ias15_loop, force) is loop_for(ias15.ias15_loop, force)
    True
    """
    key = (factory, force.key, force.jit, force.cache, force.runtime, args,
           tuple(sorted(options.items())))
    loop = _LOOPS.get(key)
    if loop is None:
        loop = _LOOPS[key] = factory(force, *args, **options)
    return loop
