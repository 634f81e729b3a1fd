"""Reference trigger policies (the papers', periodic, always) and the evaluation commands."""
