"""Report scripts: each reruns one study behind a document and writes its figures and summary.json
into docs/generated/ (``python -m bench.reports.<name> --out DIR``)."""
