"""driftlab_client: Python client of driftlab-server (see client.py and README.md)."""

from driftlab_client.client import (FINAL_STATES, Client, DriftlabError, JobFailed, connect,
                                    load_job, plot_envelopes, summary_lines, to_dict,
                                    write_result)

__all__ = ["Client", "DriftlabError", "JobFailed", "FINAL_STATES", "connect", "load_job",
           "plot_envelopes", "summary_lines", "to_dict", "write_result"]
