#include <iostream>

#include "app/cli_common.h"
#include "app/commands.h"
#include "cl/cl_runtime.h"

namespace narval {

Command addDevicesCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("devices", "List OpenCL platforms and devices with their limits");
  auto json = std::make_shared<bool>(false);
  sub->add_flag("--json", *json, "Print a JSON array");
  addThreadsOption(sub);
  return {sub, [json]() {
            const std::vector<DeviceInfo> devices = listDevices();
            std::cout << (*json ? devicesJson(devices) : devicesText(devices));
            if (devices.empty() && !*json) std::cerr << "narval: no OpenCL device found\n";
            return devices.empty() ? 1 : 0;
          }};
}

}  // namespace narval
