// The standard Robot Raconteur types (com.robotraconteur.*) in a page: one import for the dashboard
// and for pages that use the client package directly. See docs/dashboard.md "Standard types".
//
//   import { RobdefOutline, standardDescriber, typedText, imageToBitmap } from "./std/index.js";
//   const types = standardDescriber(new RobdefOutline(camera.$definitions));
//   const d = types.describe("RobotState", "com.robotraconteur.robotics.robot");
//   typedText(state, d);            // "{ts: 2024-05-01T12:00:00.25Z (0.1 s ago), ..., robot_state_flags: enabled | ready, ...}"

export { RendererRegistry } from "./registry.js";
export { TypeDescriber, resolveName, findNamed, qualifyType, fieldAt } from "./describe.js";
export { standardRegistry, standardDescriber, STANDARD_ANNOTATORS } from "./standard.js";
export { typedText, fieldText, memberText } from "./typed_text.js";
export { decodeImage, checkImage } from "./image_decode.js";
export { compressedFormat, checkCompressedImage, COMPRESSED_FORMATS } from "./compressed_image.js";
export { imageToBitmap, pictureToBitmap, isCompressedEncoding } from "./image_bitmap.js";
export { STANDARD_IMAGE_ENCODINGS, PIXEL_FORMATS, encodingNames } from "./image_encodings.js";
export { formatUuid, isNilUuid, uuidBytes } from "./uuid.js";
export { formatIdentifier } from "./identifier.js";
export { formatTime, formatDuration, timeParts, timeSeconds, isoTime, ageText, durationText, comparableClock } from "./datetime.js";
export { formatPose, formatTransform, formatRotation, quaternionToRpy } from "./geometry.js";
export { enumName, formatEnum, flagNames, formatFlags, isFlagEnum, flagEnumFor, codeEnumFor, formatCodes } from "./enums.js";
export { siUnitText, unitsOf, unitsFieldFor } from "./units.js";
export { plotRole, leaveOutOfPlot, typedNumericFields, sensorTimestamp } from "./plot_fields.js";
export { deviceInfoRows } from "./device_info.js";
export { formatDataType } from "./datatype.js";
export { FrameDecoder } from "./frame_decoder.js";
export { RobdefOutline } from "./robdef_outline.js";
// stdpanels-a (issue 54): wrenches, laser scans
export { formatWrench, wrenchParts } from "./wrench.js";
export { scanGeometry, scanPoints, intensityRange, drawScan, scanText, ScanAssembler } from "./laserscan.js";
// stdpanels-c (issue 54): joint trajectories, PID gains, parameter infos
export { trajectorySeries, trajectoryText, drawTrajectory } from "./trajectory.js";
export { formatPid, formatParameterInfo, varText } from "./param.js";
// stdpanels-d (issue 54): point clouds
export { packCloud, colorCloud, colorModeFor, unpackRgb, CloudAssembler, boundsText, cloudText, drawCloud, COLOR_MODES, CLOUD_TYPES, CLOUD_PART_TYPES } from "./pointcloud.js";
export { CloudDecoder } from "./pointcloud_decoder.js";
