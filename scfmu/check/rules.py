"""What a finding of ``scfmu check`` is measured against: a clause of the FMI standard (class ``standard``)
or a rule of this project that the standard does not make (class ``robustness``).

Each failing check names a rule key (``Fail(kind, detail, rule=...)`` in the child; the parent derives one
from the kind otherwise); :func:`classify` adds ``class`` and ``rule`` (the text) to the row. The standard's
clauses are cited by the section of FMI 2.0.4 and the named section of FMI 3.0.x that states them."""

from __future__ import annotations

STANDARD, ROBUSTNESS = "standard", "robustness"

# key: (class, FMI 2.0 text, FMI 3.0 text); a robustness rule has the same text for both versions
RULES: dict[str, tuple[str, str, str]] = {
    "state_machine": (STANDARD,
                      "FMI 2.0.4 §3.2.3 / §4.2.4 (calling sequence state machines of Model Exchange and "
                      "Co-Simulation): a function called in a state where the tables do not allow it returns "
                      "fmi2Error",
                      "FMI 3.0 'State Machine' sections of Model Exchange and Co-Simulation (and 'Status Returned "
                      "by Functions'): a function called in a state the state machine does not allow returns "
                      "fmi3Error"),
    "allowed_call": (STANDARD,
                     "FMI 2.0.4 §3.2.3 / §4.2.4: a call the state machine allows, with valid arguments, must work",
                     "FMI 3.0 'State Machine' sections: a call the state machine allows, with valid arguments, "
                     "must work"),
    "guid": (STANDARD,
             "FMI 2.0.4 §2.1.5 (fmi2Instantiate): the GUID must match the modelDescription's; the instance is "
             "refused (NULL) otherwise",
             "FMI 3.0 'Instantiation' (fmi3Instantiate*): the instantiationToken must match; NULL otherwise"),
    "status_value": (STANDARD,
                     "FMI 2.0.4 §2.1.3 (Status Returned by Functions): the status is one of fmi2OK ... fmi2Pending",
                     "FMI 3.0 'Status Returned by Functions': the status is one of fmi3OK ... fmi3Fatal"),
    "unknown_vr": (STANDARD,
                   "FMI 2.0.4 §2.1.7 (Getting and Setting Variable Values) with §2.1.3: a value reference the "
                   "modelDescription does not define is an invalid argument: fmi2Error",
                   "FMI 3.0 'Getting and Setting Variable Values' with 'Status Returned by Functions': an unknown "
                   "value reference is an invalid argument: fmi3Error"),
    "determinism": (STANDARD,
                    "FMI 2.0.4 §2.1.8 (Getting and Setting the Complete FMU State): a restored state continues "
                    "as the saved one did",
                    "FMI 3.0 'Getting and Setting the Complete FMU State': a restored state continues as the "
                    "saved one did"),
    # -------------------------------------------------------------------------------- robustness
    "runs": (ROBUSTNESS, "R0: the calls a master makes with the start values and the default experiment's "
                         "step (until the unit asks to end) return OK or Warning", ""),
    "returns": (ROBUSTNESS, "R1: every call returns within the call bound, for any argument (a hang is a "
                            "failure, whatever the argument)", ""),
    "no_crash": (ROBUSTNESS, "R2: no argument and no call order ends the process (a signal, abort or exit)", ""),
    "finite_outputs": (ROBUSTNESS, "R3: with finite inputs and finite arguments, no output is NaN or Inf with "
                                   "status OK/Warning (a non-finite input may pass through: the standard "
                                   "allows it)", ""),
    "invalid_argument": (ROBUSTNESS, "R4: a NULL pointer, a NaN or negative step or time, a NULL or empty FMU "
                                     "state is refused with an error status", ""),
    "stale_handle": (ROBUSTNESS, "R5: a freed instance or FMU-state handle is refused, also after its address "
                                 "was given to a new one (the standard leaves a freed handle undefined)", ""),
    "memory": (ROBUSTNESS, "R6: resident memory does not grow with repeated instantiate/free and load/unload "
                           "cycles", ""),
    "threads": (ROBUSTNESS, "R7: instances on different threads do not influence each other", ""),
    "start_time": (ROBUSTNESS, "R8: any finite start time is either refused at initialisation or runs with "
                               "bounded calls and finite outputs", ""),
    "load": (ROBUSTNESS, "R9: the binary loads and exports every function the standard requires", ""),
    "checker": (ROBUSTNESS, "an error of the checker itself (please report it)", ""),
}

# the rule of a failure that did not name one, by its kind
BY_KIND = {"hang": "returns", "crash": "no_crash", "nonfinite": "finite_outputs", "leak": "memory",
           "memory": "memory", "wrong_state": "state_machine", "error_status": "runs",
           "invalid_status": "status_value", "nondeterministic": "determinism", "wrong_status": "invalid_argument",
           "missing_function": "load", "load": "load", "checker_error": "checker", "stale_handle": "stale_handle",
           "no_binary": "load"}


def rule_text(key: str, version: int) -> str:
    cls, t2, t3 = RULES[key]
    return t2 if cls == ROBUSTNESS or version == 2 else t3


def classify(row: dict, version: int) -> dict:
    """Adds ``class`` and ``rule`` to a failed row (in place; returns it). Static findings (the
    modelDescription, the archive) are the standard's (FMI 2.0.4 §2.2 / FMI 3.0 'FMU Description')."""
    if row.get("status") != "fail":
        return row
    key = row.get("rule") or BY_KIND.get(row.get("kind", ""), "")
    if key in RULES:
        row["class"] = RULES[key][0]
        row["rule"] = rule_text(key, version)
    elif row.get("interface") is None:  # a static check: the modelDescription's schema and rules, the archive
        row["class"] = STANDARD
        row["rule"] = ("FMI 2.0.4 §2.2 (FMI Description Schema) and §2.3 (FMU Distribution)" if version == 2 else
                       "FMI 3.0 'FMI Description Schema' and 'FMU Distribution'")
    else:
        row["class"] = ROBUSTNESS
        row["rule"] = rule_text("checker", version)
    return row
