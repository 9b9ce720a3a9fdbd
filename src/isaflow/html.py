"""Self-contained HTML pages of the report's tables (readable in a browser and inside the Snakemake report)."""

STYLE = ("<style>body{font-family:sans-serif;font-size:13px} table{border-collapse:collapse} "
         "td,th{border:1px solid #bbb;padding:3px 6px;vertical-align:top;text-align:left} "
         "th{background:#eee;position:sticky;top:0}</style>")


def page(title, body):
    """A self-contained HTML page (readable in a browser and inside the Snakemake report)."""
    return (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{title}</title>{STYLE}</head>"
            f"<body>{body}</body></html>\n")
