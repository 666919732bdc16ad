"""What a compiled function does with its arrays, for tests, read from numba's typed IR and from
the parsed LLVM module, never from LLVM's text.

- :func:`row_offsets`: how a function indexes an array argument, from numba's typed IR (the IR
  after inlining and type inference, kept by a pass added to numba's nopython pipeline through
  ``pipeline_class``, numba's documented way to extend its compiler): an index numba knows at
  compile time (``static_getitem``/``static_setitem``, or an integer literal) is a constant
  offset; any other is computed at run time.
- :func:`reference_count_calls`: the functions of the optimised module that call numba's
  runtime ``NRT_incref``/``NRT_decref``, from the module as LLVM itself parses it (llvmlite's
  ``parse_assembly``: functions, blocks, instructions and their operands).
"""

from __future__ import annotations

import functools

from llvmlite import binding as llvm
from numba import njit, types
from numba.core import ir
from numba.core.compiler import CompilerBase, DefaultPassBuilder
from numba.core.compiler_machinery import AnalysisPass, register_pass
from numba.core.typed_passes import NopythonTypeInference

_KEPT: list = []


@register_pass(mutates_CFG=False, analysis_only=True)
class _KeepTypedIR(AnalysisPass):
    """Keeps the typed IR (the function's IR and its variables' types) of the compile."""

    _name = "quadcruise_keep_typed_ir"

    def __init__(self):
        AnalysisPass.__init__(self)

    def run_pass(self, state):
        _KEPT.append((state.func_ir.copy(), dict(state.typemap)))
        return False


class _TypedIRPipeline(CompilerBase):
    """numba's nopython pipeline with :class:`_KeepTypedIR` right after type inference."""

    def define_pipelines(self):
        pm = DefaultPassBuilder.define_nopython_pipeline(self.state)
        pm.add_pass_after(_KeepTypedIR, NopythonTypeInference)
        pm.finalize()
        return [pm]


@functools.lru_cache(maxsize=8)
def typed_ir(py_func, signature):
    """The typed IR of a fresh, uncached compile of ``py_func`` with ``signature`` (the engine's
    error model): the function's ``numba.core.ir.FunctionIR`` and the types of its variables."""
    del _KEPT[:]
    njit(signature, error_model="numpy", pipeline_class=_TypedIRPipeline)(py_func)
    return _KEPT[0]


def _aliases(func_ir, argument: str) -> set[str]:
    """The variables that hold the argument ``argument`` (itself, and its names in the bodies of
    the helpers inlined into the function)."""
    names: set[str] = set()
    assigns = [s for b in func_ir.blocks.values() for s in b.body if isinstance(s, ir.Assign)]
    for s in assigns:
        if isinstance(s.value, ir.Arg) and s.value.name == argument:
            names.add(s.target.name)
    grown = True
    while grown:
        grown = False
        for s in assigns:
            if isinstance(s.value, ir.Var) and s.value.name in names and s.target.name not in names:
                names.add(s.target.name)
                grown = True
    return names


def _index_values(func_ir, typemap):
    """A function ``values(var)`` giving the integers an index variable can hold, where numba's
    typed IR fixes them at compile time (a literal, a module-level int, a sum or product of such,
    an item of a tuple of such, or the variable of a loop over a ``range`` of such, which LLVM
    unrolls), else None."""
    definitions: dict[str, list] = {}
    for block in func_ir.blocks.values():
        for s in block.body:
            if isinstance(s, ir.Assign):
                definitions.setdefault(s.target.name, []).append(s.value)
    ops = {"+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b}

    def of_value(value, seen):
        if isinstance(value, (ir.Const, ir.Global, ir.FreeVar)):
            return {value.value} if isinstance(value.value, int) and not isinstance(value.value, bool) else None
        if isinstance(value, ir.Var):
            return of_var(value.name, seen)
        if not isinstance(value, ir.Expr):
            return None
        if value.op == "getattr":  # a module's int: L.PHI
            module = definitions.get(value.value.name, [None])[0]
            if isinstance(module, (ir.Global, ir.FreeVar)):
                attr = getattr(module.value, value.attr, None)
                return {attr} if isinstance(attr, int) and not isinstance(attr, bool) else None
            return None
        if value.op == "binop" and value.fn.__name__ in ("add", "sub", "mul"):
            a, b = of_value(value.lhs, seen), of_value(value.rhs, seen)
            op = ops[{"add": "+", "sub": "-", "mul": "*"}[value.fn.__name__]]
            return None if a is None or b is None else {op(x, y) for x in a for y in b}
        if value.op == "pair_first":  # the variable of a for loop: over its range
            step = definitions.get(value.value.name, [None])[0]
            if isinstance(step, ir.Expr) and step.op == "iternext":
                return of_range(step.value, seen)
        if value.op == "cast":
            return of_value(value.value, seen)
        if value.op == "phi":  # where branches join: any of the incoming values
            found = set()
            for incoming in value.incoming_values:
                got = of_value(incoming, seen)
                if got is None:
                    return None
                found |= got
            return found
        if value.op == "static_getitem" and isinstance(value.index, int):  # j, c = (A, B) if k else (C, D)
            tuples = of_tuple(value.value, seen)
            if tuples is None:
                return None
            found: set[int] = set()
            for items in tuples:
                got = of_value(items[value.index], seen) if value.index < len(items) else None
                if got is None:
                    return None
                found |= got
            return found
        return None

    def of_tuple(var, seen):
        if var.name in seen:
            return None
        tuples = []
        for value in definitions.get(var.name, [None]):
            if isinstance(value, ir.Var):
                got = of_tuple(value, seen | {var.name})
            elif isinstance(value, ir.Expr) and value.op == "exhaust_iter":
                got = of_tuple(value.value, seen | {var.name})
            elif isinstance(value, ir.Expr) and value.op == "phi":
                got = []
                for incoming in value.incoming_values:
                    more = of_tuple(incoming, seen | {var.name})
                    if more is None:
                        got = None
                        break
                    got += more
            elif isinstance(value, ir.Expr) and value.op == "build_tuple":
                got = [value.items]
            else:
                got = None
            if got is None:
                return None
            tuples += got
        return tuples

    def of_range(var, seen):
        value = definitions.get(var.name, [None])
        if len(value) != 1:
            return None
        value = value[0]
        if isinstance(value, ir.Var):
            return of_range(value, seen)
        if isinstance(value, ir.Expr) and value.op == "getiter":
            return of_range(value.value, seen)
        if isinstance(value, ir.Expr) and value.op == "call" and not value.kws:
            function = definitions.get(value.func.name, [None])[0]
            if isinstance(function, ir.Global) and function.value is range:
                bounds = [of_value(a, seen) for a in value.args]
                if all(b is not None and len(b) == 1 for b in bounds):
                    return set(range(*[b.pop() for b in bounds]))
        return None

    def of_var(name, seen):
        kind = typemap.get(name)
        if isinstance(kind, types.IntegerLiteral):
            return {kind.literal_value}
        if name in seen or name not in definitions:
            return None
        found: set[int] = set()
        for value in definitions[name]:
            got = of_value(value, seen | {name})
            if got is None:
                return None
            found |= got
        return found

    return lambda var: of_var(var.name, frozenset())


def row_offsets(py_func, signature, argument: str) -> tuple[set[int], int]:
    """How ``py_func`` compiled with ``signature`` indexes its array argument ``argument`` (its
    parameter's name, followed into inlined helpers): the entries it reads or writes at offsets
    fixed at compile time (:func:`_index_values`), and how many reads and writes use an index
    computed at run time. A row read through offsets that numba folded as constants has none of
    the latter. Of a 2-D array indexed by (row, column), the column: the offset within a row."""
    func_ir, typemap = typed_ir(py_func, signature)
    names = _aliases(func_ir, argument)
    values = _index_values(func_ir, typemap)
    tuples = {
        s.target.name: s.value.items
        for block in func_ir.blocks.values()
        for s in block.body
        if isinstance(s, ir.Assign) and isinstance(s.value, ir.Expr) and s.value.op == "build_tuple"
    }
    constant, computed = set(), 0

    def index(static, var):
        nonlocal computed
        if isinstance(static, tuple):
            static = static[-1]
        if var is not None and var.name in tuples:
            var = tuples[var.name][-1]
        if isinstance(static, int):
            constant.add(static)
            return
        got = values(var) if var is not None else None
        if got is None:
            computed += 1
        else:
            constant.update(got)

    for block in func_ir.blocks.values():
        for s in block.body:
            if isinstance(s, ir.Assign) and isinstance(s.value, ir.Expr) and s.value.op == "getitem":
                if s.value.value.name in names:
                    index(None, s.value.index)
            elif isinstance(s, ir.Assign) and isinstance(s.value, ir.Expr) and s.value.op == "static_getitem":
                if s.value.value.name in names:
                    index(s.value.index, s.value.index_var)
            elif isinstance(s, ir.StaticSetItem) and s.target.name in names:
                index(s.index, s.index_var)
            elif isinstance(s, ir.SetItem) and s.target.name in names:
                index(None, s.index)
    return constant, computed


@functools.lru_cache(maxsize=8)
def _module(py_func, signature):
    dispatcher = njit(signature, error_model="numpy")(py_func)
    return llvm.parse_assembly("".join(dispatcher.inspect_llvm().values()))


def reference_count_calls(py_func, signature) -> list[str]:
    """The functions, other than numba's Python-facing wrappers, that call ``NRT_incref`` or
    ``NRT_decref`` in a fresh, uncached compile of ``py_func`` with ``signature``."""
    calls = []
    for function in _module(py_func, signature).functions:
        if function.is_declaration or function.name.startswith("_ZN7cpython"):
            continue
        for block in function.blocks:
            for instruction in block.instructions:
                if instruction.opcode == "call":
                    callee = list(instruction.operands)[-1].name
                    if callee in ("NRT_incref", "NRT_decref"):
                        calls.append(function.name)
    return calls
