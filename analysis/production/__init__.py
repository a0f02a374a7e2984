"""Production QA over a population of stored measurements: capability, control charts, stations, golden units,
and the exchange formats (CSV, JSON, Q-DAS AQDEF). No Qt; numbers in SI, customary units only in what is shown.

    production_stats(population, limits_version) -> ProductionStats     (analysis.production.summary)
    propose_limits(population_of_golden_units, k) -> limits document      (analysis.production.golden)
"""
from analysis.production.capability import Capability, capability
from analysis.production.control_chart import DEFAULT_BASELINE, RULES, Alarm, ControlChart, control_chart
from analysis.production.golden import propose_limits
from analysis.production.stations import StationComparison, compare_stations
from analysis.production.summary import ParameterStats, ProductionStats, production_stats

__all__ = ["Alarm", "Capability", "ControlChart", "DEFAULT_BASELINE", "ParameterStats", "ProductionStats", "RULES",
           "StationComparison", "capability", "compare_stations", "control_chart", "production_stats", "propose_limits"]
