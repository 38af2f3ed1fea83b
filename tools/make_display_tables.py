"""Copy the display step's matrices from colour-science into catalog/render/data/display_tables.npz.

Run after upgrading colour-science; tests/test_display.py checks the file equals a fresh copy.
"""

from catalog.render.display import write_display_tables

if __name__ == "__main__":
    print(f"wrote {write_display_tables()}")
