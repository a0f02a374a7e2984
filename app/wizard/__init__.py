"""The measurement wizard (the Measure page): app.wizard.wizard.MeasureWizard."""
from app.wizard.wizard import MeasureWizard

__all__ = ["MeasureWizard"]
