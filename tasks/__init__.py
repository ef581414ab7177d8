"""Tasks: the missions (``missions/``), the worlds drawn for them or run without physics (``worlds/``), and the
studies that sweep them (``studies/``). ``MISSIONS`` names every mission ``teamsim run`` knows."""
from __future__ import annotations

from teamsim.tasks.missions.bounding_overwatch import BoundingOverwatchMission
from teamsim.tasks.missions.box_pushing import BoxPushingMission
from teamsim.tasks.missions.explore import ExploreMission
from teamsim.tasks.missions.formation import FormationMission
from teamsim.tasks.missions.hazardous_waste import HazardousWasteMission
from teamsim.tasks.missions.janitorial import JanitorialMission
from teamsim.tasks.missions.navigate import NavigateMission
from teamsim.tasks.missions.wander import WanderMission

MISSIONS = {mission.name: mission for mission in (WanderMission(), NavigateMission(), HazardousWasteMission(),
                                                     BoxPushingMission(), ExploreMission(), JanitorialMission(),
                                                     BoundingOverwatchMission(), FormationMission())}
