"""The QA page: verdicts against limits, validity, and the report export."""
