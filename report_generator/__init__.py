"""The report: ``python report_generator/report.py`` (``make report``) writes ``report/``."""
