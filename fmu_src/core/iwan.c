/* iwan.c -- implementation of iwan.h (in progress: see issue "The Masing/Iwan hysteresis element"). */
#include "iwan.h"

const char *iwan_status_text(iwan_status status)
{
    switch (status) {
    case IWAN_OK: return "ok";
    case IWAN_ERR_NONFINITE: return "NaN or infinite input";
    case IWAN_ERR_BAD_TABLE: return "bad curve table";
    case IWAN_ERR_NOT_CONCAVE: return "curve table is not concave";
    case IWAN_ERR_BAD_PARAM: return "bad parameter";
    case IWAN_ERR_NOT_CONVERGED: return "periodic loop did not close";
    case IWAN_ERR_BAD_STATE: return "bad state";
    }
    return "unknown status";
}
