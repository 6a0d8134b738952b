"""The report page (`lagrangian report`, System.report): one self-contained HTML page built
from the output stage's pieces (drawings, animations, plots) and MathML of our own."""
