"""State machines as controllers: states with an entry action, a per-tick control law and exit
events, each naming the next state. The engine ticks a machine like any other controller."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from reactmocap.errors import ConfigError, UnknownKeyError
from reactmocap.sim.controllers.base import Controller
from reactmocap.sim.world import World

__all__ = ["Event", "State", "StateMachine", "Transition", "after", "when"]

#: an exit condition: ``event(world, t, t_in_state) -> bool``
Event = Callable[[World, float, float], bool]


def after(seconds: float) -> Event:
    """Fires once the state has lasted ``seconds``."""
    if not seconds >= 0:
        raise ConfigError(f"after() needs seconds >= 0, got {seconds!r}")
    return lambda _w, _t, t_in: t_in >= seconds - 1e-12


def when(predicate: Callable[[World], bool]) -> Event:
    """Fires when ``predicate(world)`` holds."""
    return lambda w, _t, _t_in: bool(predicate(w))


@dataclass(frozen=True)
class State:
    """One state: ``law`` acts at every tick spent in it (``None``: nothing), ``on_enter`` once
    on entry with the world and time, ``exits`` are ``(event, next state)`` tried in order at
    each tick; a state without exits is final."""

    name: str
    law: Controller | None = None
    on_enter: Callable[[World, float], None] | None = None
    exits: tuple[tuple[Event, str], ...] = ()


@dataclass(frozen=True)
class Transition:
    time: float
    source: str
    target: str


@dataclass(eq=False)
class StateMachine:
    """A controller made of :class:`State` objects, starting in ``initial``. Each tick it first
    takes at most one transition (the first exit event that fires), then runs the current
    state's law. :attr:`transitions` logs what happened."""

    states: Sequence[State]
    initial: str
    control_every: int = 1
    transitions: list[Transition] = field(default_factory=list)

    def __post_init__(self) -> None:
        names = [s.name for s in self.states]
        if len(set(names)) != len(names):
            raise ConfigError(f"state names must be unique, got {names}")
        self._by_name = {s.name: s for s in self.states}
        for s in self.states:
            for _, target in s.exits:
                self._state(target, f"state {s.name!r} exits to")
            if s.law is not None and s.law.control_every != self.control_every:
                raise ConfigError(
                    f"state {s.name!r}: its law ticks every {s.law.control_every} steps, the "
                    f"machine every {self.control_every}"
                )
        self._state(self.initial, "initial state")
        if self.control_every < 1:
            raise ConfigError(f"control_every must be >= 1, got {self.control_every!r}")
        self.current = self._by_name[self.initial]
        self._entered = 0.0
        self._fresh = True

    def _state(self, name: str, what: str) -> State:
        try:
            return self._by_name[name]
        except KeyError:
            raise UnknownKeyError(f"{what} {name!r}: no such state; states are "
                                  f"{sorted(self._by_name)}") from None  # fmt: skip

    def reset(self, world: World) -> None:
        self.current = self._by_name[self.initial]
        self.transitions.clear()
        self._fresh = True
        for s in self.states:
            if s.law is not None:
                s.law.reset(world)

    def _enter(self, state: State, world: World, t: float) -> None:
        self.current = state
        self._entered = t
        if state.on_enter is not None:
            state.on_enter(world, t)

    def control(self, world: World, t: float) -> None:
        if self._fresh:
            self._fresh = False
            self._enter(self.current, world, t)
        for event, target in self.current.exits:
            if event(world, t, t - self._entered):
                self.transitions.append(Transition(t, self.current.name, target))
                self._enter(self._by_name[target], world, t)
                break
        if self.current.law is not None:
            self.current.law.control(world, t)
