"""Copies, repeated operations and dead writes taken out of a tape; what stays runs in its order.

The translation (:mod:`dirac.codegen.tape_source`) gives one instruction per operation of the
source, and the generated step loops are full of plain copies: the locals of an inlined helper
bound to its arguments (``_i1_v0_ = _a_x_0``), loop variables nobody reads, bookkeeping left by
the unrolling (``i = 1`` after an unrolled loop). On the RATTLE loop of a double pendulum in its
angles, ``MOV`` was 23 % of the 20,700 instructions a ``rattle-8`` step executes, and the
machine costs about 6 ns an instruction whatever it does (a switch over the operation numbers:
:mod:`dirac.codegen.tape_machine`). Three classical passes over the tape's control-flow graph
(Aho, Lam, Sethi & Ullman, *Compilers*, 2nd ed., Sect. 8.5, 9.1 and 9.2) remove them:

* local value numbering: an operation repeated in a basic block on registers none of which was
  written since (``0.5 * h`` in every row of a Newton matrix, the index ``o + 0`` of an unrolled
  loop) becomes a copy of its first result; the same IEEE 754 operation on the same values
  gives the same double (operands are never commuted: ``a + b`` and ``b + a`` may carry
  different NaN payloads), and one that can stop the machine stopped it the first time;
* copy propagation within a basic block: where ``MOV a, b`` is followed in its block by a read
  of ``a`` with neither ``a`` nor ``b`` written in between, the read takes ``b``; a copy is the
  exact value, bits, signed zero and NaN alike, so the operation reading it gives the same
  result;
* dead-code elimination: a write to a register nobody reads before it is written again or the
  tape ends (liveness, a backward problem) goes, when its operation cannot stop the machine:
  ``MOV``, ``ADD``, ``SUB``, ``MUL``, ``NEG``, ``ABS``. A division (a zero divisor stops the
  machine), a load (an index out of range) and the :mod:`math` functions (a domain error) stay,
  so the machine stops where it stopped and the caller reruns the call interpreted as before.

Then a jump to a jump goes straight to the final target, and a jump to the next instruction
goes. Every value the tape stores is computed by the same operations on the same operands as
before, in the same order: the results are the interpreter's to the last bit (checked by the
tests against the unoptimised tape and Python on programs made to defeat each pass, random
programs and the step loops of the corpus). The arrays, the registers the call fills
(parameters, lengths, constants) and the memory written are unchanged; only the registers'
values at the end, which nobody reads, may differ.

Measured (instructions executed per ``rattle-8`` step, plain -> optimised, at ``dt = 0.0244``,
the step ``auto`` takes for ``t_end = 100`` of the double pendulum, and 0.01): the double pendulum in its angles 20,700 -> 17,200 (``MOV`` 4,800 ->
2,200 of them), the heavy top in Euler angles 20,700 -> 17,400, the triple pendulum in angles
35,500 -> 30,200, the Cartesian double pendulum 9,300 -> 8,700 (its constant-mass loop is mostly
products); the time of a step on the machine compiled at the install, optimised / plain (21
alternated calls of 100 steps, median of the ratios, load 3.5): 0.78, 0.84, 0.80 and 0.94.
The passes take 4-12 ms per loop, once per process, next to 17-55 ms of translation.
"""

from __future__ import annotations

__all__ = ["optimise", "REMOVABLE"]

_MOV, _ADD, _SUB, _MUL, _DIV, _NEG, _LOAD, _STORE, _LOAD2, _STORE2 = range(10)
_JMP, _JLT, _JLE, _JEQ, _ABS = range(10, 15)
_ATAN2 = 27
_JUMPS = frozenset({_JMP, _JLT, _JLE, _JEQ})
_CONDITIONAL = frozenset({_JLT, _JLE, _JEQ})
#: operations that never stop the machine: a write of theirs that nobody reads can go
REMOVABLE = frozenset({_MOV, _ADD, _SUB, _MUL, _NEG, _ABS})

Instruction = tuple[int, int, int, int, int]


def _defined(instruction: Instruction) -> int:
    """The register an instruction writes (-1: none)."""
    op = instruction[0]
    if op in _JUMPS or op == _STORE or op == _STORE2:
        return -1
    return instruction[1]


def _used_fields(op: int) -> tuple[int, ...]:
    """Positions (1-4) in ``(op, a, b, c, d)`` of the registers an instruction reads."""
    if op == _MOV or op == _NEG or op == _ABS or 15 <= op <= 26:
        return (2,)
    if op in (_ADD, _SUB, _MUL, _DIV, _ATAN2) or op in _CONDITIONAL:
        return (2, 3)
    if op == _LOAD:
        return (3,)
    if op == _LOAD2:
        return (3, 4)
    if op == _STORE:
        return (2, 3)
    if op == _STORE2:
        return (2, 3, 4)
    return ()


def _successors(code: list[Instruction], position: int) -> tuple[int, ...]:
    """Where the machine goes after ``position`` (``len(code)``: the end of the tape)."""
    op, target = code[position][0], code[position][1]
    if op == _JMP:
        return (target,)
    if op in _CONDITIONAL:
        return (position + 1, target) if target != position + 1 else (target,)
    return (position + 1,)


def _blocks(code: list[Instruction]) -> tuple[list[int], list[list[int]]]:
    """Basic blocks: their first instructions (sorted, the end of the tape last, as an empty
    block) and the successor blocks of each."""
    n = len(code)
    leaders = {0, n}
    for position, instruction in enumerate(code):
        if instruction[0] in _JUMPS:
            leaders.add(instruction[1])
            leaders.add(position + 1)
    starts = sorted(x for x in leaders if 0 <= x <= n)
    index = {start: k for k, start in enumerate(starts)}
    successors: list[list[int]] = [[] for _ in starts]
    for k in range(len(starts) - 1):
        for target in _successors(code, starts[k + 1] - 1):
            if index[target] not in successors[k]:
                successors[k].append(index[target])
    return starts, successors


def _reads(code: list[Instruction]) -> list[tuple[int, ...]]:
    """Per instruction, the positions (1-4) of the registers it reads."""
    fields = {op: _used_fields(op) for op in {instruction[0] for instruction in code}}
    return [fields[instruction[0]] for instruction in code]


def _propagate_copies(code: list[Instruction]) -> list[Instruction]:
    """Reads of ``a`` replaced by ``b`` where the copy ``MOV a, b`` is available (see the
    module docstring) within a basic block; the copies themselves stay (dead-code
    elimination takes them).

    Within a block only: a copy is taken from the block's own instructions, never from the
    blocks before it. The global problem (copies met on every path into a block) took 0.3 %
    more of the instructions of the RATTLE loop of a double pendulum in its angles (17,836 ->
    17,534 a ``rattle-8`` step) and cost ten times the time of this pass to solve in Python."""
    starts, _ = _blocks(code)
    reads = _reads(code)
    out = list(code)
    for start, end in zip(starts, starts[1:]):
        forward: dict[int, int] = {}
        backward: dict[int, set[int]] = {}
        for position in range(start, end):
            instruction = out[position]
            if forward and reads[position]:
                parts = list(instruction)
                for f in reads[position]:
                    parts[f] = forward.get(parts[f], parts[f])
                instruction = out[position] = tuple(parts)  # type: ignore[assignment]
            target = _defined(instruction)
            if target < 0:
                continue
            source = forward.pop(target, None)
            if source is not None:
                backward[source].discard(target)
            for a in backward.pop(target, ()):
                del forward[a]
            if instruction[0] == _MOV and instruction[2] != target:
                forward[target] = instruction[2]
                backward.setdefault(instruction[2], set()).add(target)
    return out


#: operations whose result depends on their operand registers alone, and that give the same
#: result when repeated on the same values (one that stops the machine stopped it the first time)
_PURE = frozenset({_ADD, _SUB, _MUL, _DIV, _NEG, _ABS, _ATAN2, *range(15, 27)})


def _reuse_values(code: list[Instruction]) -> list[Instruction]:
    """Within a basic block, an operation repeated on the same registers with none of them
    written since (``0.5 * h`` of every row of a Newton matrix) becomes a copy of the first
    result (local value numbering, without commuting operands: ``a + b`` and ``b + a`` may
    carry different NaN payloads); copy propagation and dead-code elimination then take it."""
    starts, _ = _blocks(code)
    out = list(code)
    for start, end in zip(starts, starts[1:]):
        held: dict[tuple[int, int, int], int] = {}  # (op, b, c) -> the register holding the result
        keys: dict[int, list[tuple[int, int, int]]] = {}  # register -> the entries that name it
        for position in range(start, end):
            instruction = out[position]
            op, a, b, c, _ = instruction
            target = _defined(instruction)
            key = (op, b, c if op in (_ADD, _SUB, _MUL, _DIV, _ATAN2) else -1)
            holder = held.get(key) if op in _PURE else None
            if holder is not None:  # a copy (to itself when a holds the value already: dead-code elimination takes it)
                out[position] = (_MOV, a, holder, 0, 0)
                if holder == a:
                    continue
            if target < 0:
                continue
            for stale in keys.pop(target, ()):
                held.pop(stale, None)
            if op in _PURE and holder is None and target != b and (key[2] < 0 or target != c):
                held[key] = target
                for register in {b, key[2], target} - {-1}:
                    keys.setdefault(register, []).append(key)
    return out


def _remove_dead(code: list[Instruction]) -> list[Instruction] | None:
    """``code`` without the writes nobody reads (of operations that cannot stop the machine),
    jumps renumbered; None when there is none."""
    starts, successors = _blocks(code)
    count = len(starts) - 1
    reads = _reads(code)
    defined = [_defined(instruction) for instruction in code]
    uses = [0] * len(code)
    for position, instruction in enumerate(code):
        mask = 0
        for f in reads[position]:
            mask |= 1 << instruction[f]
        uses[position] = mask
    # backward problem over the blocks' summaries, registers as bits of an integer
    gen, kill = [0] * count, [0] * count
    for k in range(count):
        live, killed = 0, 0
        for position in range(starts[k + 1] - 1, starts[k] - 1, -1):
            target = defined[position]
            if target >= 0:
                bit = 1 << target
                live &= ~bit
                killed |= bit
            live |= uses[position]
        gen[k], kill[k] = live, killed
    live_in = [0] * (count + 1)
    changed = True
    while changed:
        changed = False
        for k in range(count - 1, -1, -1):
            live = 0
            for s in successors[k]:
                live |= live_in[s]
            live = gen[k] | (live & ~kill[k])
            if live != live_in[k]:
                live_in[k] = live
                changed = True
    dead = set()
    for k in range(count):
        live = 0
        for s in successors[k]:
            live |= live_in[s]
        for position in range(starts[k + 1] - 1, starts[k] - 1, -1):
            instruction = code[position]
            target = defined[position]
            if target >= 0 and instruction[0] in REMOVABLE and (not (live >> target) & 1 or (
                    instruction[0] == _MOV and instruction[2] == target)):  # unread, or a copy to itself
                dead.add(position)
                continue
            if target >= 0:
                live &= ~(1 << target)
            live |= uses[position]
    if not dead:
        return None
    return _without(code, dead)


def _without(code: list[Instruction], removed: set[int]) -> list[Instruction]:
    """``code`` without the instructions at ``removed``, each jump to one of them sent to the
    next instruction kept (where the machine would have gone on)."""
    new_index = [0] * (len(code) + 1)
    kept = 0
    for position in range(len(code) + 1):
        new_index[position] = kept
        if position < len(code) and position not in removed:
            kept += 1
    out = []
    for position, instruction in enumerate(code):
        if position in removed:
            continue
        if instruction[0] in _JUMPS:
            op, target, b, c, d = instruction
            instruction = (op, new_index[target], b, c, d)
        out.append(instruction)
    return out


def _thread_jumps(code: list[Instruction]) -> list[Instruction]:
    """Each jump to an unconditional jump sent to that jump's final target, and unconditional
    jumps to the next instruction removed."""
    n = len(code)

    def final(target: int) -> int:
        seen = set()
        while target < n and code[target][0] == _JMP and target not in seen:
            seen.add(target)
            target = code[target][1]
        return target

    threaded = [(op, final(a), b, c, d) if op in _JUMPS else (op, a, b, c, d) for op, a, b, c, d in code]
    useless = {position for position, (op, a, *_rest) in enumerate(threaded) if op == _JMP and a == position + 1}
    return _without(threaded, useless) if useless else threaded


def optimise(code: list[Instruction], rounds: int = 4) -> list[Instruction]:
    """``code`` with repeated operations reused, copies propagated, dead writes removed and
    jumps threaded (see the module docstring), repeated while it shrinks (a copy of a copy, an
    operation repeated on copies: at most ``rounds`` times)."""
    for _ in range(rounds):
        propagated = _propagate_copies(_reuse_values(code))
        smaller = _remove_dead(propagated)
        if smaller is None:
            code = propagated
            break
        code = smaller
    return _thread_jumps(code)
