"""AMBF itself as the judge: the same scene played in AMBF's simulator (headless, through
adfkit's own AMBF plugin) and in adfkit, compared body by body (``adfkit parity``)."""
