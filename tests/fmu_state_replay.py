"""The FMU-state replay the families' state tests share: take an instance's state (FMI 2.0 or 3.0), serialize
it, and run the same continuation three times from it (right after the get, after setting the state back,
after deserializing the bytes): a restored state must continue bit for bit."""

from __future__ import annotations


def replay_three_ways(f, fmi: int, run):
    """`f` an open `scfmu.fmu.Fmu`, `run()` the continuation (its result compared by the caller); returns the
    three results and the serialized state."""
    s = f.slave
    if fmi == 2:
        get, put, ser, des, free = (s.getFMUstate, s.setFMUstate, s.serializeFMUstate, s.deSerializeFMUstate,
                                    s.freeFMUstate)
    else:
        get, put, ser, des, free = (s.getFMUState, s.setFMUState, s.serializeFMUState, s.deserializeFMUState,
                                    s.freeFMUState)
    state = get()
    blob = ser(state)
    a = run()
    put(state)
    b = run()
    restored = des(blob)
    put(restored)
    c = run()
    free(state)
    free(restored)
    return a, b, c, blob
