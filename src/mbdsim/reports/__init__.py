"""Report writers (validation report: Markdown + self-contained HTML)."""
