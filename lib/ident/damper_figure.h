#pragma once
/// @file The figure of a damper fit (`rths identify --damper --plot`, docs/identification.md "The
/// MR damper"): per record, training then held out, force against velocity and against
/// displacement, measured and model. A fit that failed or gave an implausible value says so first
/// in the title (FitStatus::Mark), so that the picture is not taken for a working model.
#include <string>
#include <vector>

#include "ident/damper_model.h"
#include "io/plot.h"
#include "io/rig_record.h"

namespace rths::ident {

/// The figure's title: "MR damper <what>: measured (blue) and fitted model (vermillion)" for a fit
/// that is ok and plausible, else "<mark> | MR damper <what>: measured (blue), model (vermillion)"
/// (shorter, so that the line fits the figure's width). `what`: "at 1 A", "(current input)", ...
std::string DamperFigureTitle(const FitStatus& status, const std::string& what);

/// The figure (file comment): two panels per record, over the record's last 60 % (the steady
/// cycles), each titled with the record's name, fitted or held out, and Eq. 31 on f [%]; no legend
/// over the loops (the title names the colours). Its name is "damper_fit".
io::Figure DamperFitFigure(const DamperModelFit& fit, const std::vector<io::RigRecord>& training,
                           const std::vector<io::RigRecord>& held, const std::string& what);

}  // namespace rths::ident
