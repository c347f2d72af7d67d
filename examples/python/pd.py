#!/usr/bin/env python3
"""The study's `pd` law served from Python: its trace in lockstep is the Rust `pd`'s, bit for bit.

    [controller]
    law = "pd"
    command = ["python3", "pd.py"]    # the plant appends --run-id ID
"""

from amb_testbed_controller import PD, serve

if __name__ == "__main__":
    serve(PD)
