"""Missions and studies: each sets up a world, defines success and measures."""
from __future__ import annotations

from teamsim.tasks.hazardous_waste import HazardousWasteMission
from teamsim.tasks.navigate import NavigateMission
from teamsim.tasks.wander import WanderMission

MISSIONS = {mission.name: mission for mission in (WanderMission(), NavigateMission(), HazardousWasteMission())}
