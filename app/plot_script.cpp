#include "app/plot_script.h"

#include <cstdlib>
#include <fstream>
#include <string>

namespace meniscus::app {

bool run_plot_script(const std::filesystem::path& out, const char* script_name, const char* script,
                     const char* errors_name) {
    const std::filesystem::path path = out / script_name;
    const std::filesystem::path errors = out / errors_name;
    {
        std::ofstream f(path);
        f << script;
    }
    const std::string command = std::string(PLOT_PYTHON) + " '" + path.string() + "' '" +
                                out.string() + "' 2> '" + errors.string() + "'";
    if (std::system(command.c_str()) != 0)
        return false;
    std::filesystem::remove(errors);
    return true;
}

}  // namespace meniscus::app
